#!/usr/bin/env python3
"""What `pbflow serve` holds live on this machine (docs/serve.md). A benchmark, not a test: it
reports, it asserts nothing.

1. Real time: the dam break with the scene's clock at --fps (default 30: `--param fps=30`, 4
   substeps a frame, dt 1/120 s as at 60 fps), --size (default 640x360), fluid style, one viewer,
   at a row of spacings: the real-time factor, frames a second shown, and a frame's cost split
   into simulate, draw, encode and send (wall clock, medians); the largest size that holds 0.95.
2. Viewers: one server at one spacing, its real-time factor with 0, 1 and 8 viewers and with 8
   and a stalled one, in rounds that take each condition in turn (one sitting, the machine's
   drift shared). The factor is read by a probe that connects for one frame every few seconds:
   the frame carries the factor of the second before it connected.
3. The frame budget: at a few budgets, the settings the run took, its compression and cost.
4. The stream's bytes at 1280x720, H.264 and JPEG.

Usage: bench/serve.py [--binary build/pbflow] [--seconds 8] [--spacings 0.08,0.06,0.05,0.045,0.04]
                      [--fps 30] [--size 640x360] [--codec jpeg] [--viewers-at 0.03] [--rounds 3] [--budgets 25,50,100]
                      [--parts real_time,viewers,budgets,stream] [--out bench/results/serve_lavapipe.md]"""
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

IMAGE = ("--width", "640", "--height", "360")


def measure(port, seconds, warm_up=3.0, codec="jpeg"):
    """One viewer's frames over `seconds`, after `warm_up`: their stats."""
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
    return {"about": about, "rows": rows, "frames_per_s": len(rows) / elapsed,
            "rtf": statistics.median(r["realtime_factor"] for r in rows[len(rows) // 2:]),
            "bytes_per_frame": statistics.mean(r["bytes"] for r in rows),
            "simulate_ms": med("simulate_ms"), "draw_ms": med("draw_ms"), "encode_ms": med("encode_ms"),
            "send_ms": med("send_ms"), "mbit_s": 8 * sum(r["bytes"] for r in rows) / elapsed / 1e6}


def reader(port, stop):
    """A viewer that reads every frame until `stop` is set."""
    c = Client(port, timeout=30)
    while not stop.is_set():
        c.frame()
    c.sock.close()


def probe(port):
    """The real-time factor of the second before this connection: one frame's."""
    c = Client(port, timeout=30)
    rtf = c.frame()[2]["realtime_factor"]
    c.sock.close()
    return rtf


def real_time(a, lines):
    substeps = round(120 / a.fps)  # the scene's 2 substeps at 60 fps: dt 1/120 s at any clock
    lines += [f"## Real time at {a.fps} fps, {a.size}", "",
              f"The dam break at `--param fps={a.fps}` ({substeps} substeps a frame), {a.size}, fluid style, one viewer "
              f"on loopback, {a.codec}; {a.seconds:g} s measured after 3 s. A real-time factor of 1 is {a.fps} frames a second of "
              "simulated time each second. Costs are wall-clock medians per frame.", "",
              "| spacing (m) | run | real-time factor | frames/s shown | simulate ms | draw ms | encode ms | send ms | Mbit/s |",
              "|---|---|---|---|---|---|---|---|---|"]
    width, height = a.size.split("x")
    holding = None
    for spacing in [float(s) for s in a.spacings.split(",")]:
        server = Server("dam_break", ("--param", f"particle_spacing={spacing}", "--param", f"fps={a.fps}",
                                      "--width", width, "--height", height))
        try:
            m = measure(server.port, a.seconds, codec=a.codec)
        finally:
            server.stop()
        lines.append(f"| {spacing:g} | {m['about']} | {m['rtf']:.2f} | {m['frames_per_s']:.1f} | {m['simulate_ms']:.1f} | "
                     f"{m['draw_ms']:.1f} | {m['encode_ms']:.1f} | {m['send_ms']:.2f} | {m['mbit_s']:.2f} |")
        print(lines[-1], flush=True)
        if m["rtf"] >= 0.95:
            holding = m["about"].split(",")[1].strip()
    lines += ["", f"Largest that holds a real-time factor of 0.95: {holding or 'none of these'}.", ""]


def viewers(a, lines):
    conditions = ((0, False), (1, False), (8, False), (8, True))
    server = Server("dam_break", ("--param", f"particle_spacing={a.viewers_at}", *IMAGE))
    samples = {c: [] for c in conditions}
    about = json.loads(Client(server.port).receive()[1])["about"]
    try:
        time.sleep(3)
        for _ in range(a.rounds):
            for readers, stalled in conditions:
                stop, threads, idle = threading.Event(), [], None
                for _ in range(readers):
                    threads.append(threading.Thread(target=reader, args=(server.port, stop), daemon=True))
                    threads[-1].start()
                if stalled:  # connects, never reads
                    idle = Client(server.port)
                    idle.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
                time.sleep(2)  # the viewers at work for a full window of the factor
                for _ in range(3):
                    samples[(readers, stalled)].append(probe(server.port))
                    time.sleep(1.5)
                stop.set()
                for t in threads:
                    t.join()
                if idle:
                    idle.sock.close()
                time.sleep(1)  # the server frees a viewer's place once it sees the close
    finally:
        server.stop()
    base = statistics.median(samples[(0, False)])
    lines += ["## Viewers", "", f"{about}, 640x360, fluid style: {a.rounds} rounds of each condition in turn on one server, "
              "3 probes each (the factor of the second before a probe connects); medians.", "",
              "| viewers | real-time factor | against 0 viewers | spread (min-max) |", "|---|---|---|---|"]
    for (readers, stalled), values in samples.items():
        label = f"{readers}" + (" + 1 stalled" if stalled else "")
        med = statistics.median(values)
        lines.append(f"| {label} | {med:.3f} | {100 * (med / base - 1):+.1f} % | {min(values):.3f}-{max(values):.3f} |")
        print(lines[-1], flush=True)
    lines.append("")


def budgets(a, lines):
    lines += ["## The frame budget", "",
              f"The dam break at {a.viewers_at:g} m, 640x360, fluid style, `--frame-budget MS`, one viewer; {a.seconds:g} s "
              "measured after 3 s (the front is measured first, from the start). Settings are method@iterations/substeps; "
              "frame ms is simulate + draw, median.", "",
              "| budget ms | front measured (ms, mean compression %) | settings taken | frame ms | mean compression % | real-time factor |",
              "|---|---|---|---|---|---|"]
    for budget in [float(b) for b in a.budgets.split(",")]:
        server = Server("dam_break", ("--param", f"particle_spacing={a.viewers_at}", "--frame-budget", f"{budget:g}", *IMAGE))
        try:
            m = measure(server.port, a.seconds)
        finally:
            server.stop()
        rows = m["rows"]
        taken = []
        for r in rows:
            s = f"{r['setting']}/{r['substeps']}"
            if not taken or taken[-1] != s:
                taken.append(s)
        front = ", ".join(f"{p['setting']}/{p['substeps']} {p['simulate_ms']:.0f} {100 * p['mean_compression']:.3f}"
                          for p in rows[-1]["front"])
        lines.append(f"| {budget:g} | {front} | {' → '.join(taken)} | "
                     f"{statistics.median(r['simulate_ms'] + r['draw_ms'] for r in rows):.1f} | "
                     f"{100 * statistics.mean(r['mean_compression'] for r in rows):.3f} | {m['rtf']:.2f} |")
        print(lines[-1], flush=True)
    lines.append("")


def stream(a, lines):
    lines += ["## The stream at 1280x720", "",
              "The dam break at 0.02 m, fluid style: bytes a frame, as a rate at the scene's 60 fps, whatever rate this "
              "machine draws at.", "", "| codec | kB a frame | Mbit/s at 60 fps |", "|---|---|---|"]
    for codec in ("h264", "jpeg"):
        server = Server("dam_break", ("--width", "1280", "--height", "720"))
        try:
            m = measure(server.port, a.seconds, codec=codec)
        finally:
            server.stop()
        lines.append(f"| {codec} | {m['bytes_per_frame'] / 1e3:.1f} | {8 * 60 * m['bytes_per_frame'] / 1e6:.2f} |")
        print(lines[-1], flush=True)
    lines.append("")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--binary", default="build/pbflow")
    p.add_argument("--seconds", type=float, default=8)
    p.add_argument("--spacings", default="0.08,0.06,0.05,0.045,0.04")
    p.add_argument("--fps", type=int, default=30)
    p.add_argument("--size", default="640x360")
    p.add_argument("--codec", default="jpeg", choices=("jpeg", "h264"))
    p.add_argument("--viewers-at", type=float, default=0.03)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--budgets", default="25,50,100")
    p.add_argument("--parts", default="real_time,viewers,budgets,stream")
    p.add_argument("--out", default="bench/results/serve_lavapipe.md")
    a = p.parse_args()
    os.environ["PBFLOW_BINARY"] = a.binary
    lines = [f"# pbflow serve, live on this machine ({datetime.date.today()})", "", f"`{' '.join(sys.argv)}`", ""]
    parts = {"real_time": real_time, "viewers": viewers, "budgets": budgets, "stream": stream}
    for name in a.parts.split(","):
        parts[name](a, lines)
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print(f"written: {a.out}")


if __name__ == "__main__":
    main()
