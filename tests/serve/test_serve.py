"""`pbflow serve` as viewers and hostile clients meet it, on loopback (docs/serve.md): the page,
the frames, the commands, several viewers, a stalled one, and every malformed or oversized
request answered with an error or a closed connection while the run goes on.

Usage: test_serve.py PBFLOW_BINARY (run by ctest). Prints "N passed, N failed"."""
import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_support import REMAKE_SECONDS, Client, OneServer, Server  # noqa: E402

if len(sys.argv) > 1:
    os.environ["PBFLOW_BINARY"] = sys.argv.pop(1)


def http(port, request, timeout=10):
    """The raw answer to a raw request ('' where the server closed without one)."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(request)
        answer = b""
        try:
            while True:
                chunk = s.recv(65536)
                if not chunk:
                    break
                answer += chunk
        except (ConnectionResetError, socket.timeout):
            pass
    return answer.decode("latin-1")


def status_of(answer):
    return int(answer.split(" ")[1]) if answer.startswith("HTTP/") else None


class ServeTest(OneServer, unittest.TestCase):
    def test_the_page_is_served_whole_and_nothing_else(self):
        answer = http(self.server.port, b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")
        self.assertEqual(status_of(answer), 200)
        self.assertIn("<title>pbflow live</title>", answer)
        self.assertIsNone(re.search(r"(src|href)=\"(https?:)?//", answer), "the page loads something from elsewhere")
        for path in ("/etc/passwd", "/../../etc/passwd", "/index.html", "/ws/x", "/%2e%2e/etc/passwd", "/%2e%2e/"):
            other = http(self.server.port, f"GET {path} HTTP/1.1\r\nHost: x\r\n\r\n".encode())
            # Nothing but the page: a path that normalises to "/" (/%2e%2e/) gets the page itself.
            self.assertTrue(status_of(other) == 404 or other == answer, f"{path}: {other[:80]!r}")
        self.assertEqual(status_of(http(self.server.port, b"POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\n\r\n")),
                         405)

    def test_malformed_and_oversized_requests_get_an_error_or_a_closed_connection(self):
        for request in (b"GARBAGE\r\n\r\n", b"GET / HTTP/9.9\r\n\r\n", b"\x00\xff\xfe\r\n\r\n",
                        b"GET / HTTP/1.1\r\nHost: x\r\nX-Big: " + b"a" * 100000 + b"\r\n\r\n",
                        b"GET /ws HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\r\n"):
            answer = http(self.server.port, request)
            code = status_of(answer)
            self.assertTrue(code is None or code >= 400, f"{request[:30]!r} answered {answer[:60]!r}")
        self.assert_still_serving()

    def test_frames_arrive_numbered_with_their_measures(self):
        viewer = Client(self.server.port)
        op, hello = viewer.receive()
        self.assertEqual(json.loads(hello)["type"], "hello")
        numbers = []
        for _ in range(5):
            number, jpeg, stats = viewer.frame()
            numbers.append(number)
            self.assertEqual(jpeg[:3], b"\xff\xd8\xff", "not a JPEG")
            self.assertEqual(stats["frame"], number)
            self.assertEqual(stats["setting"], "pbf@2")
            self.assertGreaterEqual(stats["mean_compression"], 0)
            self.assertGreater(stats["potential_energy"], 0)
        self.assertEqual(numbers, sorted(set(numbers)), "frame numbers go forward")
        viewer.sock.close()

    def test_pause_holds_the_frame_step_draws_one_and_resume_goes_on(self):
        viewer = Client(self.server.port)
        viewer.frame()
        viewer.send(json.dumps({"cmd": "pause"}))
        deadline, held = time.time() + 2, None
        while time.time() < deadline:  # frames drawn before the pause still come
            viewer.sock.settimeout(max(deadline - time.time(), 0.01))
            try:
                held = viewer.frame()[0]
            except (socket.timeout, TimeoutError):
                break
        viewer.sock.settimeout(1.5)
        with self.assertRaises((socket.timeout, TimeoutError)):
            number = viewer.frame()[0]
            self.fail(f"frame {number} drawn while paused (held {held})")
        viewer.sock.settimeout(20)
        viewer.send(json.dumps({"cmd": "step"}))
        number, _, stats = viewer.frame()
        self.assertTrue(stats["paused"])
        viewer.send(json.dumps({"cmd": "resume"}))
        later = [viewer.frame()[0] for _ in range(3)]
        self.assertGreater(later[-1], number)
        viewer.sock.close()

    def test_bad_commands_are_answered_and_a_long_one_closes_its_connection(self):
        viewer = Client(self.server.port)
        for command, expect in (("{\"cmd\": \"explode\"}", "unknown command"), ("{\"cmd\": 5}", "string 'cmd'"),
                                ("not json", "syntax error"), ("[" * 60 + "]" * 60, "string 'cmd'"),
                                ("[" * 100 + "]" * 100, "nested deeper")):
            viewer.send(command)
            for _ in range(200):
                op, data = viewer.receive()
                if op == 1 and json.loads(data).get("type") == "error":
                    self.assertIn(expect, json.loads(data)["message"], command[:20])
                    break
            else:
                self.fail(f"no error for {command[:20]}")
        viewer.send(b"\x01\x02", opcode=2)
        viewer.send("x" * 100000)
        with self.assertRaises((ConnectionError, OSError, socket.timeout)):
            for _ in range(10000):
                viewer.receive()
        viewer.sock.close()
        self.assert_still_serving()

    def frame_where(self, viewer, predicate, limit=200):
        for _ in range(limit):
            frame = viewer.frame()
            if predicate(frame):
                return frame
        self.fail("no such frame")

    def test_setting_style_and_camera_change_live_and_bad_values_are_refused(self):
        viewer = Client(self.server.port, timeout=REMAKE_SECONDS)
        viewer.send(json.dumps({"cmd": "setting", "method": "ldc", "iterations": 1}))
        self.frame_where(viewer, lambda f: f[2]["setting"] == "ldc@1")
        viewer.send(json.dumps({"cmd": "setting", "method": "pbf", "iterations": 2}))
        self.frame_where(viewer, lambda f: f[2]["setting"] == "pbf@2")
        # Paused, a new view or style is drawn at once, as a frame of its own.
        viewer.send(json.dumps({"cmd": "step"}))
        before = self.frame_where(viewer, lambda f: f[2]["paused"])
        viewer.send(json.dumps({"cmd": "camera", "orbit_x": 0.8, "orbit_y": 0.3, "zoom": 0.7}))
        after = self.frame_where(viewer, lambda f: f[0] > before[0])
        self.assertTrue(after[2]["paused"])
        self.assertNotEqual(after[1], before[1], "the new view drew the same picture")
        viewer.send(json.dumps({"cmd": "style", "style": "density"}))
        styled = self.frame_where(viewer, lambda f: f[0] > after[0])
        self.assertNotEqual(styled[1], after[1], "the new style drew the same picture")
        for command, expect in (({"cmd": "camera", "zoom": 100}, "'zoom' must be a number in [0.1, 10]"),
                                ({"cmd": "camera", "orbit_x": "left"}, "'orbit_x'"),
                                ({"cmd": "style", "style": "glitter"}, "--style must be"),
                                ({"cmd": "setting", "method": "sph", "iterations": 2}, "'method'"),
                                ({"cmd": "setting", "method": "pbf", "iterations": 1.5}, "whole number"),
                                ({"cmd": "setting", "method": "pbf", "iterations": 17}, "'iterations'")):
            self.assertIn(expect, viewer.error_for(command))
        viewer.send(json.dumps({"cmd": "style", "style": "particles"}))
        viewer.send(json.dumps({"cmd": "resume"}))
        self.frame_where(viewer, lambda f: not f[2]["paused"])
        viewer.sock.close()

    def test_another_scene_from_a_command_and_only_a_built_in_one(self):
        viewer = Client(self.server.port, timeout=REMAKE_SECONDS)
        viewer.send(json.dumps({"cmd": "scene", "name": "drop"}))
        dropped = self.frame_where(viewer, lambda f: f[2]["scene"] == "drop")
        self.assertIn("drop", dropped[2]["about"])
        self.assertLess(dropped[2]["time"], 0.5, "a new scene starts from its start")
        for command, expect in (({"cmd": "scene", "name": "/etc/passwd"}, "'name' must be a built-in scene: cup, dam_break"),
                                ({"cmd": "scene", "name": "../scenes/dam_break.json"}, "built-in scene"),
                                ({"cmd": "scene", "name": 5}, "built-in scene"),
                                ({"cmd": "scene"}, "built-in scene")):
            self.assertIn(expect, viewer.error_for(command))
        viewer.send(json.dumps({"cmd": "scene", "name": "hydrostatic"}))
        self.frame_where(viewer, lambda f: f[2]["scene"] == "hydrostatic")
        viewer.sock.close()

    def test_the_tank_shakes_and_stops_on_command_and_bad_steering_is_refused(self):
        viewer = Client(self.server.port, timeout=REMAKE_SECONDS)
        for command, expect in (({"cmd": "drag", "obstacle": 0, "position": [0.1, 0.1, 0.1]}, "the scene has 0 obstacle(s)"),
                                ({"cmd": "drag", "position": [0.1, 0.1, 0.1]}, "'obstacle' must be an obstacle's index"),
                                ({"cmd": "drag", "obstacle": 0.5, "position": [0, 0, 0]}, "'obstacle' must be"),
                                ({"cmd": "drag", "obstacle": 0, "position": [0, 0]}, "'position' must be three numbers"),
                                ({"cmd": "drag", "obstacle": 0, "position": [0, "up", 0]}, "'position'"),
                                ({"cmd": "drag", "obstacle": 0, "release": "yes"}, "'release' must be true or false"),
                                ({"cmd": "shake", "amplitude": 2}, "'amplitude' must be a number in [0, 1]"),
                                ({"cmd": "shake", "amplitude": 0.01, "period": 0}, "'period' must be a number in [0.05, 60]"),
                                ({"cmd": "shake", "amplitude": 0.01, "axis": [0, 0, 0]}, "'axis' must be a direction"),
                                ({"cmd": "shake", "amplitude": 0.5, "period": 0.1}, "faster than"),
                                ({"cmd": "tilt", "angle": 45}, "'angle' must be a number in [-30, 30]"),
                                ({"cmd": "tilt", "angle": 10, "axis": [0, 0, 0]}, "'axis' must be a direction"),
                                ({"cmd": "tilt", "angle": "steep"}, "'angle'"),
                                ({"cmd": "emit"}, "'on' must be true or false"),
                                ({"cmd": "emit", "on": "yes"}, "'on' must be true or false")):
            self.assertIn(expect, viewer.error_for(command))
        viewer.send(json.dumps({"cmd": "shake", "amplitude": 0.01, "axis": [0, 0, 2]}))
        shaking = self.frame_where(viewer, lambda f: f[2]["shake"] is not None)[2]["shake"]
        self.assertEqual(shaking["axis"], [0, 0, 1])
        self.assertGreater(shaking["period"], 0.2, "not the tank's first sloshing mode")
        self.frame_where(viewer, lambda f: abs(f[2]["solid_work"]) > 0)
        # Another setting carries the shaking on (and any dragged solid: Solver::carry).
        viewer.send(json.dumps({"cmd": "setting", "method": "ldc", "iterations": 1}))
        self.frame_where(viewer, lambda f: f[2]["setting"] == "ldc@1" and f[2]["shake"] is not None and
                         abs(f[2]["solid_work"]) > 0)
        viewer.send(json.dumps({"cmd": "shake", "amplitude": 0}))
        self.frame_where(viewer, lambda f: f[2]["shake"] is None)
        # A tilt turns the tank and holds it; the turn does work on the water, carried by a setting change.
        viewer.send(json.dumps({"cmd": "tilt", "angle": -10, "axis": [0, 0, 3]}))
        tilted = self.frame_where(viewer, lambda f: f[2]["tilt"] is not None and abs(f[2]["solid_work"]) > 0)[2]["tilt"]
        self.assertEqual(tilted, {"angle": -10, "axis": [0, 0, 1]})
        viewer.send(json.dumps({"cmd": "tilt", "angle": 0}))
        self.frame_where(viewer, lambda f: f[2]["tilt"] is None)
        viewer.send(json.dumps({"cmd": "setting", "method": "pbf", "iterations": 2}))
        self.frame_where(viewer, lambda f: f[2]["setting"] == "pbf@2")
        viewer.sock.close()

    def test_a_frame_budget_chooses_from_the_front_it_measured(self):
        viewer = Client(self.server.port, timeout=REMAKE_SECONDS)
        for command, expect in (({"cmd": "budget", "ms": -1}, "'ms' must be a number in [0, 10000]"),
                                ({"cmd": "budget", "ms": "fast"}, "'ms'"),
                                ({"cmd": "budget", "ms": 1e9}, "'ms'")):
            self.assertIn(expect, viewer.error_for(command))
        viewer.send(json.dumps({"cmd": "budget", "ms": 50}))
        held = self.frame_where(viewer, lambda f: f[2]["budget_ms"] == 50)[2]
        front = held["front"]
        self.assertGreaterEqual(len(front), 2)
        for cheaper, dearer in zip(front, front[1:]):  # dearer and more accurate in turn
            self.assertGreater(dearer["simulate_ms"], cheaper["simulate_ms"])
            self.assertLess(dearer["mean_compression"], cheaper["mean_compression"])
        self.assertIn((held["setting"], held["substeps"]), [(p["setting"], p["substeps"]) for p in front])
        # A setting chosen by a viewer gives the choice back: the budget is off.
        viewer.send(json.dumps({"cmd": "setting", "method": "pbf", "iterations": 2}))
        back = self.frame_where(viewer, lambda f: f[2]["budget_ms"] == 0)[2]
        self.assertNotIn("front", back)
        self.frame_where(viewer, lambda f: f[2]["setting"] == "pbf@2" and f[2]["substeps"] == 2)
        viewer.sock.close()

    def test_a_viewer_can_take_h264_starting_at_a_keyframe(self):
        viewer = Client(self.server.port)
        self.assertEqual(viewer.frame(with_kind=True)[3], 0, "JPEG until asked")
        self.assertIn("bad codec", "bad codec " + viewer.error_for({"cmd": "stream", "codec": "vp9"}))
        viewer.send(json.dumps({"cmd": "stream", "codec": "h264"}))
        kinds = []
        while len(kinds) < 12:
            number, payload, stats, kind = viewer.frame(with_kind=True)
            if kind == 0 and not kinds:
                continue  # JPEGs drawn before the switch
            kinds.append(kind)
            self.assertEqual(payload[:4], b"\x00\x00\x00\x01", "not Annex B")
            self.assertEqual(stats["bytes"], len(payload))
        self.assertEqual(kinds[0], 1, "the stream must start at a keyframe")
        self.assertIn(2, kinds, "no delta frames: every frame a keyframe")
        viewer.send(json.dumps({"cmd": "stream", "codec": "jpeg"}))
        self.frame_where(viewer, lambda f: f[1][:3] == b"\xff\xd8\xff")
        viewer.sock.close()

    def test_viewers_share_the_run_and_a_stalled_one_holds_up_no_one(self):
        first, second = Client(self.server.port), Client(self.server.port)
        a, b = first.frame()[0], second.frame()[0]
        self.assertLess(abs(a - b), 30, "two viewers, two runs?")
        stalled = Client(self.server.port)  # never reads: its socket buffers fill
        stalled.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        start = first.frame()[0]
        time.sleep(3)
        for _ in range(10):
            number = first.frame()[0]
        self.assertGreater(number, start + 5, "the frames stopped for a reader beside a stalled viewer")
        late = Client(self.server.port)  # joins at the current frame
        self.assertGreater(late.frame()[0], start)
        for c in (first, second, stalled, late):
            c.sock.close()

    def test_past_the_viewer_limit_a_connection_is_refused_and_the_rest_go_on(self):
        server = Server()  # its own: no viewer of another test still counted
        try:
            viewers = [Client(server.port) for _ in range(16)]
            with self.assertRaises((ConnectionError, OSError)):
                refused = Client(server.port)
                try:
                    refused.frame(timeout=5)
                finally:
                    refused.sock.close()
            viewers[0].frame()
            for v in viewers:
                v.sock.close()
            time.sleep(1)
            late = Client(server.port)  # the places are free again
            late.frame()
            late.sock.close()
        finally:
            server.stop()

    def test_connections_opened_and_never_finished_do_not_stop_the_run(self):
        viewer = Client(self.server.port)
        start = viewer.frame()[0]
        idle = [socket.create_connection(("127.0.0.1", self.server.port)) for _ in range(150)]
        for s in idle[:50]:
            s.sendall(b"GET / HTTP/1.1\r\n")  # a request never finished
        time.sleep(2)
        for _ in range(5):
            number = viewer.frame()[0]
        self.assertGreater(number, start + 3)
        for s in idle:
            s.close()
        viewer.sock.close()


def jpeg_size(data):
    """(width, height) from a JPEG's start-of-frame marker."""
    at = 2
    while at < len(data):
        marker, length = data[at + 1], int.from_bytes(data[at + 2:at + 4], "big")
        if marker in (0xC0, 0xC1, 0xC2):
            return int.from_bytes(data[at + 7:at + 9], "big"), int.from_bytes(data[at + 5:at + 7], "big")
        at += 2 + length
    raise ValueError("no start-of-frame marker")


class CompareTest(unittest.TestCase):
    """--compare: settings side by side from one start, one picture, each panel's measures."""

    @classmethod
    def setUpClass(cls):
        cls.server = Server("dam_break", ("--param", "particle_spacing=0.05", "--style", "particles",
                                          "--width", "96", "--height", "64", "--compare", "pbf@1,ldc@1,pbf@3"))

    @classmethod
    def tearDownClass(cls):
        cls.server.stop()

    def test_each_panel_shows_its_setting_in_one_picture(self):
        viewer = Client(self.server.port, timeout=REMAKE_SECONDS)
        for _ in range(20):
            number, image, stats = viewer.frame()
        self.assertEqual(jpeg_size(image), (3 * 96, 64))
        panels = stats["panels"]
        self.assertEqual([p["setting"] for p in panels], ["pbf@1", "ldc@1", "pbf@3"])
        # One start, one scene: the more iterations, the less compression once the column falls.
        self.assertGreater(panels[0]["mean_compression"], panels[2]["mean_compression"])
        self.assertEqual(stats["setting"], "pbf@1")
        viewer.sock.close()

    def test_restart_and_a_new_scene_take_every_panel_and_settings_stay(self):
        viewer = Client(self.server.port, timeout=REMAKE_SECONDS)
        viewer.send(json.dumps({"cmd": "restart"}))
        restarted = None
        for _ in range(100):
            restarted = viewer.frame()[2]
            if restarted["time"] == 0:
                break
        self.assertEqual(restarted["time"], 0)
        starts = {round(p["potential_energy"], 9) for p in restarted["panels"]}
        self.assertEqual(len(starts), 1, "the panels did not restart from one start")
        for command in ({"cmd": "setting", "method": "pbf", "iterations": 2}, {"cmd": "budget", "ms": 30}):
            self.assertIn("each panel of --compare keeps its setting", viewer.error_for(command))
        viewer.send(json.dumps({"cmd": "scene", "name": "hydrostatic"}))
        for _ in range(200):
            stats = viewer.frame()[2]
            if stats["scene"] == "hydrostatic":
                break
        self.assertEqual(stats["scene"], "hydrostatic")
        self.assertEqual([p["setting"] for p in stats["panels"]], ["pbf@1", "ldc@1", "pbf@3"])
        viewer.sock.close()


class ServeLifetimeTest(unittest.TestCase):
    def test_sigint_and_sigterm_stop_it_cleanly(self):
        for sig in (signal.SIGINT, signal.SIGTERM):
            server = Server()
            viewer = Client(server.port)
            viewer.frame()
            start = time.time()
            self.assertEqual(server.stop(sig), 0)
            self.assertLess(time.time() - start, 20)

    def test_bad_compare_and_budget_options_are_one_line(self):
        for options, expect in ((["--compare", "pbf@0"], "from 1 to 16"),
                                (["--compare", "sph@2"], "is not a setting"),
                                (["--compare", "pbf@1,pbf@2,pbf@3,pbf@4,ldc@1"], "at most 4"),
                                (["--compare", "pbf@1,pbf@2", "--frame-budget", "20"], "--frame-budget"),
                                (["--frame-budget", "-3"], "--frame-budget"),
                                (["--compare", "pbf@1,pbf@2,pbf@3,pbf@4", "--width", "16384"], "wider than a JPEG")):
            answer = subprocess.run([os.environ["PBFLOW_BINARY"], "serve", "hydrostatic", "--param", "particle_spacing=0.05",
                                     "--listen", "127.0.0.1:0", *options], capture_output=True, text=True, timeout=120)
            self.assertEqual(answer.returncode, 2, answer.stderr)
            self.assertIn(expect, answer.stderr)
            self.assertEqual(len(answer.stderr.strip().splitlines()), 1, answer.stderr)

    def test_a_bad_listen_address_or_a_port_in_use_is_one_line(self):
        server = Server()
        try:
            for listen, expect in (("127.0.0.1:" + str(server.port), "cannot listen"), ("nonsense", "--listen takes")):
                answer = subprocess.run([os.environ["PBFLOW_BINARY"], "serve", "hydrostatic", "--param",
                                         "particle_spacing=0.05", "--listen", listen],
                                        capture_output=True, text=True, timeout=120)
                self.assertEqual(answer.returncode, 2, answer.stderr)
                self.assertIn(expect, answer.stderr)
        finally:
            server.stop()


if __name__ == "__main__":
    result = unittest.main(exit=False, verbosity=2).result
    failed = len(result.failures) + len(result.errors)
    print(f"{result.testsRun - failed} passed, {failed} failed")
    sys.exit(1 if failed else 0)
