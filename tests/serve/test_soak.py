"""`pbflow serve` soaked in hostile and ordinary clients for a few minutes on loopback: eight
clients at once, each doing in turn what an attacker or a careless viewer does (not UTF-8, a
message declared past the limit, fragments past it, unmasked frames, another origin, half a
request, bad JSON, a stall) and what a viewer does (watch, steer). The server's memory and open
descriptors are recorded after a warm-up and at the end; they must come back within a bound, and
the run must go on.

Usage: test_soak.py PBFLOW_BINARY [SECONDS] (run by ctest; 150 s unless given)."""
import json
import os
import random
import socket
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_support import Client, Server  # noqa: E402

MAX_MESSAGE = 4096  # ServerLimits::max_message


def descriptors(pid):
    return len(os.listdir(f"/proc/{pid}/fd"))


def hostile_round(port, rng):
    """One client's turn: something hostile or ordinary, then its connection closed."""
    kind = rng.randrange(10)
    if kind == 0:
        sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        sock.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n")  # half a request, then gone
        time.sleep(rng.random())
        sock.close()
        return
    if kind == 1:
        try:
            Client(port, origin="http://evil.example").sock.close()
        except ConnectionError:
            pass  # 403, as it must
        return
    viewer = Client(port, timeout=15)
    try:
        if kind == 2:
            viewer.send(b"\xff\xfe\xfd")
        elif kind == 3:
            viewer.send(b"{", declared=rng.choice([MAX_MESSAGE + 1, 2**31 - 1, 2**62]))
        elif kind == 4:
            for part in range(3):
                viewer.send("x" * 2048, opcode=1 if part == 0 else 0, fin=False)
        elif kind == 5:
            viewer.send(json.dumps({"cmd": "pause"}), masked=False)
        elif kind == 6:
            for payload in ("é", "[" * 100 + "]" * 100, json.dumps({"cmd": "é" * 30}, ensure_ascii=False), "{}"):
                viewer.send(payload)
        elif kind == 7:  # steers, as a viewer does
            for command in ({"cmd": "camera", "orbit_x": rng.uniform(-1, 1)}, {"cmd": "resume"},
                            {"cmd": "style", "style": rng.choice(["particles", "density"])}):
                viewer.send(json.dumps(command))
            viewer.frame()
        elif kind == 8:  # stalls for a while, then leaves
            viewer.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            time.sleep(rng.uniform(1, 12))
        else:  # watches a few frames
            for _ in range(rng.randrange(1, 6)):
                viewer.frame()
    except (ConnectionError, OSError):
        pass  # closed by the server, as the hostile kinds must be
    finally:
        viewer.sock.close()


def main():
    os.environ["PBFLOW_BINARY"] = sys.argv[1]
    seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 150
    server = Server()
    failures = []
    try:
        time.sleep(5)  # warm-up: the first frames, the encoder and a first viewer's buffers
        Client(server.port).frame()
        before_kb, before_fds = server.rss_kb(), descriptors(server.process.pid)
        end = time.time() + seconds
        rounds = [0]

        def client(seed):
            rng = random.Random(seed)
            while time.time() < end:
                try:
                    hostile_round(server.port, rng)
                    rounds[0] += 1
                except (ConnectionError, OSError):
                    pass  # refused while the places were full
        peak = server.peak_kb_while(client, 8)
        time.sleep(12)  # stalled viewers' sends time out, closed connections are let go
        viewer = Client(server.port)
        start = viewer.frame()[0]
        for _ in range(5):
            number, _, stats = viewer.frame()
        viewer.sock.close()
        after_kb, after_fds = server.rss_kb(), descriptors(server.process.pid)
        print(f"soak: {seconds:.0f} s, {rounds[0]} client rounds; memory {before_kb} kB before, peak {peak} kB, "
              f"{after_kb} kB after; {before_fds} descriptors before, {after_fds} after")
        if not server.alive():
            failures.append("the server died")
        if number <= start:
            failures.append("the frames stopped")
        if stats["scene"] != "hydrostatic":
            failures.append("a client changed the scene")
        if after_kb - before_kb > 32 * 1024:
            failures.append(f"the memory grew {after_kb - before_kb} kB")
        if after_fds > before_fds + 4:
            failures.append(f"descriptors leaked: {before_fds} -> {after_fds}")
        if rounds[0] < seconds:
            failures.append(f"only {rounds[0]} rounds: the server stopped answering")
    finally:
        server.stop()
    for f in failures:
        print("FAILED:", f)
    print(f"{0 if failures else 1} passed, {1 if failures else 0} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
