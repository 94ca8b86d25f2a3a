"""For pbflow serve's tests: a `pbflow serve` on a free loopback port, and a minimal WebSocket
client over a raw socket (RFC 6455), with the standard library only."""
import base64
import json
import os
import re
import signal
import socket
import struct
import subprocess
import threading
import time

# A command that makes the run anew (a setting, a scene, a budget's trial runs) holds every frame
# while it builds: seconds on lavapipe, several times that on two busy cores. Its wait is not a
# measure of speed (bench/ holds those), so it is long.
REMAKE_SECONDS = 120


class Client:
    def __init__(self, port, path="/ws", timeout=10, host=None, origin=None):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        key = base64.b64encode(os.urandom(16)).decode()
        origin = f"Origin: {origin}\r\n" if origin else ""
        self.sock.sendall((f"GET {path} HTTP/1.1\r\nHost: {host or f'127.0.0.1:{port}'}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\n{origin}Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(1)
            if not chunk:
                raise ConnectionError("closed during the handshake")
            head += chunk
        self.status = int(head.split(b" ")[1])
        if self.status != 101:
            raise ConnectionError(f"handshake answered {self.status}")

    def _exact(self, n):
        data = b""
        while len(data) < n:
            chunk = self.sock.recv(n - len(data))
            if not chunk:
                raise ConnectionError("closed")
            data += chunk
        return data

    def receive(self):
        """(opcode, payload) of the next message."""
        b0, b1 = self._exact(2)
        n = b1 & 0x7F
        if n == 126:
            n = struct.unpack(">H", self._exact(2))[0]
        elif n == 127:
            n = struct.unpack(">Q", self._exact(8))[0]
        return b0 & 0x0F, self._exact(n)

    def send(self, payload, opcode=1, fin=True, masked=True, declared=None):
        """One frame; `declared`: the length its header states, where that is not the payload's."""
        if isinstance(payload, str):
            payload = payload.encode()
        n = len(payload) if declared is None else declared
        bit = 0x80 if masked else 0
        head = bytes([(0x80 if fin else 0) | opcode])
        head += bytes([bit | n]) if n < 126 else (bytes([bit | 126]) + struct.pack(">H", n) if n < 65536
                                                   else bytes([bit | 127]) + struct.pack(">Q", n))
        mask = os.urandom(4) if masked else b"\0\0\0\0"
        self.sock.sendall(head + (mask if masked else b"") + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))

    def closed_with(self, timeout=10):
        """The close code the server sends (None: the connection ended without one), reading
        past whatever it sent before."""
        self.sock.settimeout(timeout)
        try:
            while True:
                op, data = self.receive()
                if op == 8:
                    return struct.unpack(">H", data[:2])[0] if len(data) >= 2 else None
        except (ConnectionError, OSError):
            return None

    def error_for(self, command, limit=300):
        """The error message the server answers `command` (a dict, sent as JSON) with."""
        self.send(json.dumps(command))
        for _ in range(limit):
            op, data = self.receive()
            if op == 1 and json.loads(data).get("type") == "error":
                return json.loads(data)["message"]
        raise AssertionError(f"no error for {command}")

    def frame(self, timeout=20, with_kind=False):
        """The next frame: (number, payload, the stats that follow it[, kind: 0 JPEG, 1 H.264
        keyframe, 2 H.264 delta])."""
        end = time.time() + timeout
        while time.time() < end:
            op, data = self.receive()
            if op == 2:
                number, _, kind = struct.unpack("<QdI", data[:20])
                op2, stats = self.receive()
                found = (number, data[24:], json.loads(stats))
                return found + (kind,) if with_kind else found
        raise TimeoutError("no frame")


class Server:
    """One `pbflow serve` on a free loopback port, small enough for lavapipe on two busy cores."""

    SMALL = ("--param", "particle_spacing=0.05", "--style", "particles", "--width", "160", "--height", "96")

    def __init__(self, scene="hydrostatic", options=SMALL):
        env = dict(os.environ)
        if "ASAN_OPTIONS" in env:  # AddressSanitizer's quarantine (256 MB) would read as growth
            env["ASAN_OPTIONS"] += ":quarantine_size_mb=4"
        self.process = subprocess.Popen(
            [os.environ.get("PBFLOW_BINARY", "build/pbflow"), "serve", scene, "--listen", "127.0.0.1:0", *options],
            stderr=subprocess.PIPE, text=True, env=env)
        self.log = []
        self.port = None
        for line in self.process.stderr:
            self.log.append(line)
            found = re.search(r"open http://127\.0\.0\.1:(\d+)/", line)
            if found:
                self.port = int(found.group(1))
                break
        if self.port is None:
            raise RuntimeError("the server did not start: " + "".join(self.log))

    def rss_kb(self):
        """The server's resident memory, kB."""
        with open(f"/proc/{self.process.pid}/status") as status:
            return int(next(line for line in status if line.startswith("VmRSS:")).split()[1])

    def serving(self):
        """Whether it is alive and a new viewer gets a frame."""
        if not self.alive():
            return False
        viewer = Client(self.port)
        viewer.frame()
        viewer.sock.close()
        return True

    def peak_kb_while(self, client, count):
        """Runs client(index) on `count` threads at once; the server's peak resident memory
        meanwhile, kB."""
        threads = [threading.Thread(target=client, args=(index,)) for index in range(count)]
        for t in threads:
            t.start()
        peak = self.rss_kb()
        while any(t.is_alive() for t in threads):
            peak = max(peak, self.rss_kb())
            time.sleep(0.2)
        return peak

    def alive(self):
        return self.process.poll() is None

    def stop(self, sig=signal.SIGINT):
        if self.process.poll() is not None:
            return self.process.returncode
        self.process.send_signal(sig)
        try:
            return self.process.wait(timeout=30)
        finally:
            if self.process.poll() is None:
                self.process.kill()


class OneServer:
    """A test class's mixin: one server for all its tests, the default scene's."""

    @classmethod
    def setUpClass(cls):
        cls.server = Server()

    @classmethod
    def tearDownClass(cls):
        cls.server.stop()

    def assert_still_serving(self):
        self.assertTrue(self.server.serving(), "the server died")
