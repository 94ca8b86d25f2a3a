"""`pbflow serve` against hostile clients and careless use, on loopback (docs/serve.md, "A server
that trusts no client"): messages that are not UTF-8 or cut inside a character, messages past the
limit declared and sent, fragments, unmasked frames, another origin, 16 viewers each sending the
worst they can (the server's memory measured), a viewer that stalls and resumes, the signals at a
low fps and during the set-up, a strict --listen checked before the set-up.

Usage: test_hostile.py PBFLOW_BINARY (run by ctest). Prints "N passed, N failed"."""
import json
import os
import signal
import socket
import struct
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_support import Client, OneServer, Server  # noqa: E402

if len(sys.argv) > 1:
    os.environ["PBFLOW_BINARY"] = sys.argv.pop(1)

SMALL = Server.SMALL
MAX_MESSAGE = 4096  # ServerLimits::max_message


def reply_to(viewer, payload, limit=300):
    """The server's error reply to `payload` (bytes or str, sent as one text frame), parsed."""
    viewer.send(payload)
    for _ in range(limit):
        op, data = viewer.receive()
        if op == 1:
            message = json.loads(data.decode("utf-8"))  # strict: the reply is UTF-8 and JSON
            if message.get("type") == "error":
                return message["message"]
    raise AssertionError(f"no error for {payload[:40]!r}")


class HostileMessagesTest(OneServer, unittest.TestCase):
    def test_text_that_is_not_utf8_closes_its_connection_only(self):
        for payload in (b"\xff\xfe{\"cmd\": \"pause\"}", b"{\"cmd\": \"\xc3\"}", b"\xed\xa0\x80"):
            viewer = Client(self.server.port)
            viewer.send(payload)
            self.assertIn(viewer.closed_with(), (1007, None), payload)
        self.assert_still_serving()

    def test_json_cut_inside_a_character_is_answered_in_utf8(self):
        viewer = Client(self.server.port)
        self.assertIn("syntax error", reply_to(viewer, "é"))
        self.assertIn("syntax error", reply_to(viewer, "{\"cmd\": \"pause\"é"))
        cut = reply_to(viewer, json.dumps({"cmd": "a" * 39 + "é" * 5}, ensure_ascii=False))
        self.assertIn("unknown command '" + "a" * 39 + "'", cut)
        self.assertIn("unknown command 'ééé", reply_to(viewer, json.dumps({"cmd": "é" * 30}, ensure_ascii=False)))
        viewer.sock.close()
        self.assert_still_serving()

    def test_a_message_past_the_limit_is_refused_from_its_header(self):
        before = self.server.rss_kb()
        viewers = []
        for declared in (MAX_MESSAGE + 1, 1_500_000_000, 2**62):
            viewer = Client(self.server.port)
            viewer.send(b"{", declared=declared)  # the header says it; the payload never comes
            started = time.time()
            self.assertIn(viewer.closed_with(timeout=5), (1009, None), declared)
            self.assertLess(time.time() - started, 5, "closed only when the payload timed out")
            viewers.append(viewer)
        grown = self.server.rss_kb() - before
        print(f"  declared 4 kB + 1, 1.5 GB and 2^62 B: the server's memory grew {grown} kB")
        self.assertLess(grown, 16 * 1024)
        for v in viewers:
            v.sock.close()
        self.assert_still_serving()

    def test_fragments_are_joined_within_the_limit(self):
        viewer = Client(self.server.port)
        viewer.send("{\"cmd\": ", fin=False)
        viewer.send("\"expl", opcode=0, fin=False)
        viewer.send(b"", opcode=9)  # a ping between fragments
        viewer.send("ode\"}", opcode=0)
        for _ in range(300):
            op, data = viewer.receive()
            if op == 1 and json.loads(data).get("type") == "error":
                self.assertIn("unknown command 'explode'", json.loads(data)["message"])
                break
        else:
            self.fail("the fragments were not joined into one command")
        for part in range(3):  # three fragments of 2 kB: past the limit together
            viewer.send("x" * 2048, opcode=1 if part == 0 else 0, fin=False)
        self.assertIn(viewer.closed_with(), (1009, None))
        self.assert_still_serving()

    def test_an_unmasked_frame_closes_its_connection(self):
        viewer = Client(self.server.port)
        viewer.send(json.dumps({"cmd": "pause"}), masked=False)
        self.assertIn(viewer.closed_with(), (1002, None))
        viewer = Client(self.server.port)
        viewer.send(b"", opcode=3)  # a reserved opcode
        self.assertIn(viewer.closed_with(), (1002, None))
        self.assert_still_serving()

    def test_only_the_servers_own_page_may_open_the_socket(self):
        port = self.server.port
        for host, origin in ((None, "http://evil.example"), (None, "null"), (None, f"http://127.0.0.1:{port + 1}"),
                             (f"evil.example:{port}", f"http://evil.example:{port}")):  # DNS rebinding
            with self.assertRaisesRegex(ConnectionError, "handshake answered 403"):
                Client(port, host=host, origin=origin)
        for host, origin in ((None, f"http://127.0.0.1:{port}"), (f"localhost:{port}", f"http://localhost:{port}"),
                             (None, None)):  # the page under either name, and a script
            viewer = Client(port, host=host, origin=origin)
            viewer.frame()
            viewer.sock.close()

    def test_sixteen_viewers_sending_the_worst_they_can_stay_within_the_bound(self):
        server = Server()  # its own: every viewer place free
        try:
            before = server.rss_kb()
            stop = time.time() + 8

            def hostile(index):
                while time.time() < stop:
                    try:
                        viewer = Client(server.port)
                        for _ in range(20):  # just under the limit, as fast as it takes them
                            viewer.send("[" * 60 + " " * (MAX_MESSAGE - 200) + "]" * 60)
                        viewer.send(b"{" * 1000, declared=2**31 - 1 if index % 2 else MAX_MESSAGE * 1000)
                        viewer.sock.close()
                    except (ConnectionError, OSError):
                        pass  # refused while the places are full, or closed: again

            peak = server.peak_kb_while(hostile, 16)
            print(f"  16 hostile viewers for 8 s: the server's memory {before} kB, peak {peak} kB")
            self.assertLess(peak - before, 64 * 1024)
            viewer = Client(server.port)
            viewer.frame()
            viewer.sock.close()
        finally:
            server.stop()

    def test_a_stalled_viewer_that_resumes_gets_whole_frames_or_is_closed(self):
        viewer = Client(self.server.port)
        viewer.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        viewer.frame()
        time.sleep(13)  # past the 10 s a send may take
        viewer.sock.settimeout(5)
        last, messages = 0, 0
        try:
            while messages < 200:
                op, data = viewer.receive()
                messages += 1
                if op == 2:
                    number, _, kind = struct.unpack("<QdI", data[:20])
                    self.assertGreater(number, last, "frames out of order: a cut frame read as the next")
                    self.assertIn(kind, (0, 1, 2))
                    self.assertEqual(data[24:27], b"\xff\xd8\xff", "a frame's payload is not a JPEG")
                    last = number
                elif op == 1:
                    json.loads(data)
                elif op != 8:
                    self.fail(f"opcode {op}: the stream is cut")
        except (ConnectionError, OSError):
            pass  # closed: the send timed out, and nothing came after what was whole
        viewer.sock.close()
        self.assert_still_serving()


class SignalsTest(unittest.TestCase):
    def assert_stops_within(self, process, sig, seconds=3.0):
        started = time.time()
        process.send_signal(sig)
        try:
            code = process.wait(timeout=30)
        finally:
            if process.poll() is None:
                process.kill()
        took = time.time() - started
        print(f"  {signal.Signals(sig).name}: stopped in {took:.2f} s")
        self.assertEqual(code, 0)
        self.assertLess(took, seconds)  # 2 s asked; the margin is a busy machine's

    def test_a_low_fps_takes_commands_and_signals_at_once(self):
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            # A frame every 1 000 s, of 2 substeps: the run waits, not works, between frames.
            server = Server(options=SMALL + ("--param", "fps=0.001", "--param", "solver.substeps=2"))
            try:
                viewer = Client(server.port, timeout=300)
                while True:  # the first frame that advanced: then a wait of 1 000 s
                    number, _, stats = viewer.frame(timeout=300)
                    if stats["time"] > 0:
                        break
                viewer.send(json.dumps({"cmd": "camera", "orbit_x": 0.5}))
                asked = time.time()
                viewer.sock.settimeout(10)
                self.assertGreater(viewer.frame(timeout=10)[0], number)
                print(f"  a camera command drawn {time.time() - asked:.2f} s after it was sent")
                self.assertLess(time.time() - asked, 3, "the command waited for the next frame")
                self.assert_stops_within(server.process, sig)
            finally:
                server.stop()

    def test_a_signal_during_the_set_up_stops_it(self):
        for sig in (signal.SIGINT, signal.SIGHUP):
            process = subprocess.Popen([os.environ["PBFLOW_BINARY"], "serve", "hydrostatic", "--listen", "127.0.0.1:0",
                                        "--iterations", "1000", *SMALL], stderr=subprocess.PIPE, text=True)
            time.sleep(2)
            self.assertIsNone(process.poll(), "the set-up ended early")
            self.assert_stops_within(process, sig)
            self.assertNotIn("open http", process.stderr.read())

    def test_a_signal_during_a_scene_switch_stops_it(self):
        server = Server("dam_break", SMALL + ("--iterations", "40"))
        try:
            viewer = Client(server.port)
            viewer.frame()
            viewer.send(json.dumps({"cmd": "scene", "name": "hydrostatic"}))  # settles at 40 iterations a step
            time.sleep(1)
            self.assert_stops_within(server.process, signal.SIGTERM)
        finally:
            server.stop()


class ListenTest(unittest.TestCase):
    def serve(self, *args):
        started = time.time()
        answer = subprocess.run([os.environ["PBFLOW_BINARY"], "serve", "hydrostatic", "--iterations", "1000", *SMALL,
                                 *args], capture_output=True, text=True, timeout=120)
        return answer, time.time() - started

    def test_the_listen_address_is_one_address_checked_before_the_set_up(self):
        for listen in ("127.0.0.1:8080,0.0.0.0:8081", "nonsense", "127.0.0.1", "127.0.0.1:99999", "::1:8080",
                       "127.0.0.1:80s", "localhost:8080", "127.0.0.1:-1"):
            answer, took = self.serve("--listen", listen)
            self.assertEqual(answer.returncode, 2, listen)
            self.assertIn("--listen takes one ADDRESS:PORT", answer.stderr)
            self.assertEqual(len(answer.stderr.strip().splitlines()), 1, answer.stderr)
            self.assertLess(took, 30, "checked after the set-up")

    def test_a_port_in_use_is_said_at_once_naming_it(self):
        taken = socket.socket()
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        try:
            answer, took = self.serve("--listen", f"127.0.0.1:{port}")
        finally:
            taken.close()
        self.assertEqual(answer.returncode, 2)
        self.assertIn(f"cannot listen on 127.0.0.1:{port}: Address already in use", answer.stderr)
        self.assertLess(took, 30, "checked after the set-up")


if __name__ == "__main__":
    result = unittest.main(exit=False, verbosity=2).result
    failed = len(result.failures) + len(result.errors)
    print(f"{result.testsRun - failed} passed, {failed} failed")
    sys.exit(1 if failed else 0)
