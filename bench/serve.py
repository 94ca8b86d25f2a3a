#!/usr/bin/env python3
"""What `pbflow serve` holds live on this machine (docs/serve.md): the dam break at a row of
spacings, 640x360, the fluid style, one viewer; each row the real-time factor, the frames a
second that reach the viewer, and a frame's cost split into simulate, draw, encode and send (wall
clock, medians over the measured seconds); then the real-time factor with 1 and 8 viewers, and
with 8 and one stalled, at one spacing; then the stream's bit rate at 1280x720, H.264 and JPEG. A benchmark, not a test: it reports, it asserts nothing.

Usage: bench/serve.py [--binary build/pbflow] [--seconds 8] [--spacings 0.04,0.03,0.025,0.02]
                      [--viewers-at 0.03] [--out bench/results/serve_lavapipe.md]"""
import argparse
import datetime
import json
import os
import socket
import statistics
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "serve"))
from serve_support import Client, Server  # noqa: E402


def measure(port, seconds, warm_up=3.0, codec="jpeg"):
    """Stats of one viewer's frames over `seconds`, after `warm_up`."""
    viewer = Client(port, timeout=30)
    _, hello = viewer.receive()
    about = json.loads(hello)["about"]
    viewer.send(json.dumps({"cmd": "stream", "codec": codec}))
    end_warm = time.time() + warm_up
    while time.time() < end_warm:
        viewer.frame()
    rows, start = [], time.time()
    while time.time() - start < seconds:
        rows.append(viewer.frame()[2])
    elapsed = time.time() - start
    viewer.sock.close()
    med = lambda k: statistics.median(r[k] for r in rows)  # noqa: E731
    return {"about": about, "frames_per_s": len(rows) / elapsed, "rtf": rows[-1]["realtime_factor"],
            "bytes_per_frame": statistics.mean(r["bytes"] for r in rows),
            "simulate_ms": med("simulate_ms"), "draw_ms": med("draw_ms"), "encode_ms": med("encode_ms"),
            "send_ms": med("send_ms"), "mbit_s": 8 * sum(r["bytes"] for r in rows) / elapsed / 1e6}


def reader(port, stop):
    """A viewer that reads every frame until `stop` is set."""
    c = Client(port, timeout=30)
    while not stop.is_set():
        c.frame()
    c.sock.close()


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--binary", default="build/pbflow")
    p.add_argument("--seconds", type=float, default=8)
    p.add_argument("--spacings", default="0.04,0.03,0.025,0.02")
    p.add_argument("--viewers-at", type=float, default=0.03)
    p.add_argument("--out", default="bench/results/serve_lavapipe.md")
    a = p.parse_args()
    os.environ["PBFLOW_BINARY"] = a.binary
    image = ("--width", "640", "--height", "360")
    lines = [f"# pbflow serve, live on this machine ({datetime.date.today()})", "",
             f"`{' '.join(sys.argv)}`: the dam break, 640x360, fluid style, one viewer on loopback; "
             f"{a.seconds:g} s measured after 3 s. The scene's clock is 60 fps: a real-time factor of 1 "
             "holds it, 0.5 is 30 fps. Costs are wall-clock medians per frame.", "",
             "| spacing (m) | run | real-time factor | frames/s shown | simulate ms | draw ms | encode ms | send ms | Mbit/s |",
             "|---|---|---|---|---|---|---|---|---|"]
    for spacing in [float(s) for s in a.spacings.split(",")]:
        server = Server("dam_break", ("--param", f"particle_spacing={spacing}", *image))
        try:
            m = measure(server.port, a.seconds)
        finally:
            server.stop()
        lines.append(f"| {spacing:g} | {m['about']} | {m['rtf']:.2f} | {m['frames_per_s']:.1f} | {m['simulate_ms']:.1f} | "
                     f"{m['draw_ms']:.1f} | {m['encode_ms']:.1f} | {m['send_ms']:.2f} | {m['mbit_s']:.2f} |")
        print(lines[-1], flush=True)
    lines += ["", f"Viewers at {a.viewers_at:g} m (the real-time factor the measuring viewer reads):", "",
              "| viewers | real-time factor | frames/s shown |", "|---|---|---|"]
    for others, stalled in ((0, False), (7, False), (7, True)):
        server = Server("dam_break", ("--param", f"particle_spacing={a.viewers_at}", *image))
        stop, threads, idle = threading.Event(), [], None
        try:
            for _ in range(others):
                threads.append(threading.Thread(target=reader, args=(server.port, stop), daemon=True))
                threads[-1].start()
            if stalled:  # connects, never reads
                idle = Client(server.port)
                idle.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            m = measure(server.port, a.seconds)
        finally:
            stop.set()
            server.stop()
        label = f"{others + 1}" + (" + 1 stalled" if stalled else "")
        lines.append(f"| {label} | {m['rtf']:.2f} | {m['frames_per_s']:.1f} |")
        print(lines[-1], flush=True)
    lines += ["", "The stream at 1280x720 (the dam break at 0.02 m, fluid style): bytes a frame, as a rate at "
              "the scene's 60 fps, whatever rate this machine draws at:", "", "| codec | kB a frame | Mbit/s at 60 fps |",
              "|---|---|---|"]
    for codec in ("h264", "jpeg"):
        server = Server("dam_break", ("--width", "1280", "--height", "720"))
        try:
            m = measure(server.port, a.seconds, codec=codec)
        finally:
            server.stop()
        lines.append(f"| {codec} | {m['bytes_per_frame'] / 1e3:.1f} | {8 * 60 * m['bytes_per_frame'] / 1e6:.2f} |")
        print(lines[-1], flush=True)
    with open(a.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"written: {a.out}")


if __name__ == "__main__":
    main()
