#!/usr/bin/env python3
"""Charts of pbflow's speed-accuracy study from DIR/runs.csv and DIR/series.csv, or of
its scaling bench from DIR/scaling.csv.

Usage: charts.py DIR   (writes DIR/*.png; `pbflow bench` runs it and leaves a copy in DIR)

  accuracy_vs_cost.png   ms per step vs time-averaged mean compression, one line per
                         method through its iteration counts (the Pareto front); below
                         it the energy gain of the same runs (a sound run has none)
  time_per_step.png      ms per step vs iterations, per method (LDC paper, Figure 7)
  compression_over_time.png, kinetic_energy.png
                         pbf@1,2,3 and ldc@1 on dam_break (LDC paper, Figures 1/4 and 6)
The charts of one scene take dam_break where the study ran it, else its first scene.
  pareto.png             with several substeps: mean compression against ms per frame (ms per
                         step x substeps), one line per method and substep count through its
                         iteration counts, a panel per scene and particle count, the front of
                         the cheapest settings in grey; below, the energy gain of the same runs
  stability_pbf.png, stability_ldc.png
                         with --stability (several substeps): each run's class
                         (stable / compressed / gains energy / diverged) over substeps x
                         iterations, a panel per scene (and per LDC strength); then only these
  adaptive.png           with --targets: iterations and ms per step each method needs to
                         reach each target mean compression
  cheapest.md            for each scene and particle count, the cheapest sound setting (ms per
                         frame) that reaches 5, 2, 1 and 0.5 % mean compression
  scaling.png            with --scaling (DIR/scaling.csv): ms per step and each pass group's
                         share against particles, log-log, with the fitted line
Accuracy and time charts use the study's largest particle count, the over-time charts
its smallest (where plain PBF at few iterations still survives); one device only.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {"pbf": dict(color="tab:blue", marker="o"), "ldc": dict(color="tab:red", marker="s")}


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def fixed(runs):
    """Runs with a fixed iteration count (adaptive runs have a target)."""
    return [r for r in runs if float(r.get("target_compression") or 0) == 0]


def scenes_of(runs):
    """The scenes the runs hold, dam_break first where it is among them (the LDC paper's)."""
    return sorted({r["scene"] for r in runs}, key=lambda s: (s != "dam_break", s))


def largest(runs, scene, pick=max):
    rows = [r for r in runs if r["scene"] == scene]
    n = pick(int(r["particles"]) for r in rows)
    return [r for r in rows if int(r["particles"]) == n], n


def by_method(rows):
    out = {}
    for r in sorted(rows, key=lambda r: int(r["iterations"])):
        out.setdefault(r["method"], []).append(r)
    return out


def step_ms(r):
    """A run's ms per step: the median over its frames where recorded (a neighbour's burst on a
    shared machine moves the mean), else the mean."""
    return float(r.get("step_ms_median") or r["step_ms_mean"])


def accuracy_vs_cost(runs, out_dir, device):
    # Runs from before energy was recorded have no energy_gain: then compression only.
    measures = [("mean_compression_avg", "mean compression, time average (%)", "log")]
    if all(r.get("energy_gain") for r in runs):
        measures.append(("energy_gain", "energy gain, largest (% of PE0)", "linear"))
    scenes = scenes_of(runs)
    fig, axes = plt.subplots(len(measures), len(scenes), figsize=(5.5 * len(scenes), 4.2 * len(measures)),
                             squeeze=False)
    for row, (column, label, scale) in zip(axes, measures):
        for ax, scene in zip(row, scenes):
            rows, n = largest(runs, scene)
            for method, rs in by_method(rows).items():
                x = [step_ms(r) for r in rs]
                y = [100 * float(r[column]) for r in rs]
                ax.plot(x, y, label=method, **STYLE.get(method, {}))
                for r, xi, yi in zip(rs, x, y):
                    ax.annotate(r["iterations"], (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=8)
            if column == "energy_gain":
                ax.axhline(1.0, color="grey", linestyle="--", linewidth=0.8)  # docs/design.md's bound
            ax.set_xlabel("ms per step")
            ax.set_ylabel(label)
            ax.set_yscale(scale)
            ax.set_title(f"{scene}, {n} particles")
            ax.legend(title="method (labels: iterations)")
    fig.suptitle(f"Accuracy against cost on {device}")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "accuracy_vs_cost.png"), dpi=110)
    plt.close(fig)


def frame_ms(r):
    return step_ms(r) * int(r["substeps"])


def sound(runs):
    """The runs a user may take: no divergence, energy gain at most 1 % of PE_0 (docs/design.md)."""
    return [r for r in runs if r["diverged"] == "0" and float(r["energy_gain"]) <= 0.01]


def pareto(runs, out_dir, device):
    panels = sorted({(r["scene"], int(r["particles"])) for r in runs})
    fig, axes = plt.subplots(2, len(panels), figsize=(5.5 * len(panels) + 1.8, 8.4), squeeze=False)
    dashes = ["-", "--", ":", "-."]
    for col, (scene, n) in enumerate(panels):
        rows = [r for r in runs if r["scene"] == scene and int(r["particles"]) == n]
        subs = sorted({int(r["substeps"]) for r in rows})
        for (column, scale), ax in zip((("mean_compression_avg", "log"), ("energy_gain", "linear")), axes[:, col]):
            for sub in subs:
                for method, rs in by_method([r for r in rows if int(r["substeps"]) == sub]).items():
                    x, y = [frame_ms(r) for r in rs], [100 * float(r[column]) for r in rs]
                    ax.plot(x, y, linestyle=dashes[subs.index(sub) % len(dashes)], label=f"{method} x {sub}",
                            **STYLE.get(method, {}))
                    for r, xi, yi in zip(rs, x, y):
                        ax.annotate(r["iterations"], (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=7)
            if column == "mean_compression_avg":
                # The front: each run that no cheaper run beats, among the sound ones.
                front, best = [], float("inf")
                for r in sorted(sound(rows), key=frame_ms):
                    if float(r["mean_compression_avg"]) < best:
                        best = float(r["mean_compression_avg"])
                        front.append((frame_ms(r), 100 * best))
                if front:
                    ax.step(*zip(*front), where="post", color="grey", linewidth=3, alpha=0.35, label="front")
                ax.set_title(f"{scene}, {n} particles")
                ax.set_ylabel("mean compression, time average (%)")
                if col == len(panels) - 1:  # beside the last panel: the lines fill the diagonal
                    ax.legend(title="method x substeps\n(labels: iterations)", fontsize=7, title_fontsize=8,
                              loc="upper left", bbox_to_anchor=(1.02, 1.0))
            else:
                ax.axhline(1.0, color="grey", linestyle="--", linewidth=0.8)  # docs/design.md's bound
                ax.set_ylabel("energy gain, largest (% of PE0)")
            ax.set_xlabel("ms per frame")
            ax.set_xscale("log")
            ax.set_yscale(scale)
    fig.suptitle(f"Compression against cost per frame on {device}")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "pareto.png"), dpi=110)
    plt.close(fig)


def time_per_step(runs, out_dir, device):
    scene = scenes_of(runs)[0]
    rows, n = largest(runs, scene)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for method, rs in by_method(rows).items():
        ax.plot([int(r["iterations"]) for r in rs], [step_ms(r) for r in rs], label=method,
                **STYLE.get(method, {}))
    ax.set_xlabel("constraint iterations")
    ax.set_ylabel("ms per step")
    ax.set_ylim(bottom=0)
    ax.set_title(f"Time per step, {scene}, {n} particles, {device}")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "time_per_step.png"), dpi=110)
    plt.close(fig)


def over_time(runs, series, out_dir, device, column, file, ylabel, scale):
    scene = scenes_of(runs)[0]
    rows, n = largest(runs, scene, min)
    wanted = [("pbf", 1), ("pbf", 2), ("pbf", 3), ("ldc", 1)]
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for method, k in wanted:
        run = next((r for r in rows if r["method"] == method and int(r["iterations"]) == k), None)
        if run is None:
            continue
        points = [s for s in series if s["run"] == run["run"]]
        ax.plot([float(s["time"]) for s in points], [scale * float(s[column]) for s in points],
                label=f"{method}@{k}", color=STYLE[method]["color"], alpha=1.0 if method == "ldc" else 0.35 + 0.2 * k)
    ax.set_xlabel("simulated time (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(f"{scene}, {n} particles, {device}")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, file), dpi=110)
    plt.close(fig)


def adaptive(runs, out_dir, device):
    rows = [r for r in runs if float(r.get("target_compression") or 0) > 0]
    if not rows:
        return
    scenes = sorted({r["scene"] for r in rows})
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.5 * len(scenes), 4.2), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        picked, n = largest(rows, scene)
        for method in ("pbf", "ldc"):
            rs = sorted((r for r in picked if r["method"] == method), key=lambda r: -float(r["target_compression"]))
            if not rs:
                continue
            x = [100 * float(r["target_compression"]) for r in rs]
            ax.plot(x, [step_ms(r) for r in rs], label=f"{method}: ms per step", **STYLE[method])
            for r, xi in zip(rs, x):
                ax.annotate(f'{float(r["iterations_used"]):.1f} it', (xi, step_ms(r)),
                            textcoords="offset points", xytext=(4, 4), fontsize=8)
        ax.set_xscale("log")
        ax.invert_xaxis()
        ax.set_xlabel("target mean compression (%)")
        ax.set_ylabel("ms per step (labels: iterations per step)")
        ax.set_title(f"{scene}, {n} particles")
        ax.legend()
    fig.suptitle(f"Adaptive iterations on {device}")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "adaptive.png"), dpi=110)
    plt.close(fig)


CLASS_COLOUR = {"stable": "#4caf50", "compressed": "#ffb300", "gains energy": "#8e24aa", "diverged": "#d32f2f"}


def strength(r):
    """The LDC panel a run belongs to: its strength (older runs.csv: K in 1/s^2)."""
    return ("strength", float(r["ldc_strength"])) if "ldc_strength" in r else ("K", float(r["ldc_k"]))


def stability_maps(runs, out_dir, device):
    scenes = sorted({r["scene"] for r in runs})
    for method in ("pbf", "ldc"):
        rows = [r for r in runs if r["method"] == method]
        if not rows:
            continue
        ks = sorted({strength(r) for r in rows})
        panels = [(scene, k) for scene in scenes for k in ks]
        fig, axes = plt.subplots(1, len(panels), figsize=(3.4 * len(panels), 3.4), squeeze=False)
        for ax, (scene, k) in zip(axes[0], panels):
            cells = [r for r in rows if r["scene"] == scene and strength(r) == k]
            its = sorted({int(r["iterations"]) for r in cells})
            subs = sorted({int(r["substeps"]) for r in cells})
            for r in cells:
                x, y = its.index(int(r["iterations"])), subs.index(int(r["substeps"]))
                ax.add_patch(plt.Rectangle((x - 0.45, y - 0.45), 0.9, 0.9, color=CLASS_COLOUR[r["class"]]))
                ax.text(x, y, f'{100 * float(r["mean_compression_avg"]):.1f}%' if r["class"] != "diverged" else "x",
                        ha="center", va="center", fontsize=8)
            ax.set_xticks(range(len(its)), its)
            ax.set_yticks(range(len(subs)), subs)
            ax.set_xlim(-0.5, len(its) - 0.5)
            ax.set_ylim(-0.5, len(subs) - 0.5)
            ax.set_xlabel("iterations")
            ax.set_ylabel("substeps per frame")
            ax.set_title(scene + (f", {k[0]} {k[1]:g}" if method == "ldc" else ""), fontsize=9)
        handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in CLASS_COLOUR.values()]
        fig.legend(handles, list(CLASS_COLOUR), loc="lower center", ncol=len(CLASS_COLOUR), fontsize=8)
        fig.suptitle(f"Where {method} breaks on {device} (cells: mean compression)", fontsize=10)
        fig.tight_layout(rect=(0, 0.08, 1, 1))
        fig.savefig(os.path.join(out_dir, f"stability_{method}.png"), dpi=110)
        plt.close(fig)


def scaling(rows, out_dir):
    """ms per step against particles (log-log) with the fit a + b N, and each pass group's ms."""
    n = [float(r["particles"]) for r in rows]
    ms = [float(r["step_ms"]) for r in rows]
    a, b = float(rows[0]["fit_intercept_ms"]), float(rows[0]["fit_ms_per_particle"])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.loglog(n, ms, "o-", color="black", label="step (GPU time)")
    ax.loglog(n, [a + b * x for x in n], "--", color="grey",
              label=f"fit {a:.3g} ms + {b * 1e6:.3g} ms per M particles")
    passes = [c[:-3] for c in rows[0] if c.endswith("_ms") and c not in ("step_ms", "wall_step_ms", "fit_intercept_ms")]
    for p in passes:
        t = [float(r[p + "_ms"]) for r in rows]
        if max(t) > 0:
            ax.loglog(n, t, ".-", lw=0.8, label=p)
    ax.set_xlabel("particles")
    ax.set_ylabel("ms per step")
    ax.set_title(f"{rows[0]['scene']} {rows[0]['method']}@{rows[0]['iterations']} on {rows[0]['device']}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "scaling.png"), dpi=110)
    plt.close(fig)


TARGETS = (0.05, 0.02, 0.01, 0.005)  # the mean compressions a user asks for


def cheapest(runs, out_dir, device):
    """cheapest.md: for each scene and particle count, the setting that reaches each target
    time-averaged mean compression at the least cost per frame (ms per step x substeps),
    among the sound runs (no divergence, energy gain at most 1 % of PE_0). An older runs.csv
    without the energy gain gets none."""
    if not runs or "energy_gain" not in runs[0]:
        return
    candidates = sound(fixed(runs))
    lines = [f"# The cheapest setting for each accuracy ({device})", "",
             "Time-averaged mean compression; cost per frame = ms per step (the median over frames) x substeps; sound runs only "
             "(no divergence, energy gain at most 1 % of PE0). Regenerate: `python3 bench/charts.py DIR`.", "",
             "| scene | particles | target | setting | ms per frame | mean compression | energy gain |",
             "|---|---|---|---|---|---|---|"]
    for key in sorted({(r["scene"], int(r["particles"])) for r in candidates}):
        group = [r for r in candidates if (r["scene"], int(r["particles"])) == key]
        for target in TARGETS:
            reach = [r for r in group if float(r["mean_compression_avg"]) <= target]
            if not reach:
                lines.append(f"| {key[0]} | {key[1]} | {100 * target:g} % | none of the runs | | | |")
                continue
            best = min(reach, key=frame_ms)
            lines.append(f"| {key[0]} | {key[1]} | {100 * target:g} % | {best['method']}@{best['iterations']} x "
                         f"{best['substeps']} | {frame_ms(best):.1f} | "
                         f"{100 * float(best['mean_compression_avg']):.2f} % | "
                         f"{100 * float(best['energy_gain']):.2f} % |")
    with open(os.path.join(out_dir, "cheapest.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out_dir = sys.argv[1]
    if os.path.exists(os.path.join(out_dir, "scaling.csv")) and not os.path.exists(os.path.join(out_dir, "runs.csv")):
        scaling(read(os.path.join(out_dir, "scaling.csv")), out_dir)
        return
    runs = read(os.path.join(out_dir, "runs.csv"))
    series = read(os.path.join(out_dir, "series.csv"))
    devices = sorted({r["device"] for r in runs})
    if len(devices) != 1:
        sys.exit(f"runs.csv mixes devices {devices}: one chart, one device")
    device = devices[0]
    cheapest(runs, out_dir, device)
    if len({r["substeps"] for r in runs}) > 1:
        if "energy_gain" in runs[0]:  # studies from before it was recorded: the maps alone
            pareto(fixed(runs), out_dir, device)
        stability_maps(runs, out_dir, device)
        return
    adaptive(runs, out_dir, device)
    runs = fixed(runs)
    if not runs:
        return
    accuracy_vs_cost(runs, out_dir, device)
    time_per_step(runs, out_dir, device)
    over_time(runs, series, out_dir, device, "mean_compression", "compression_over_time.png",
              "mean compression (%)", 100)
    over_time(runs, series, out_dir, device, "kinetic_energy", "kinetic_energy.png", "kinetic energy (J)", 1)


if __name__ == "__main__":
    main()
