"""Thread scaling of a `slosh bench` case: see `run` beside this file."""

import argparse
import datetime
import json
import os
import platform
import subprocess


def bench(slosh, case, duration, threads, repeat, spacing=None):
    cmd = [slosh, "bench", "--case", case, "--duration", str(duration), "--json", "--repeat", str(repeat)]
    if spacing is not None:
        cmd += ["--set", f"particle_spacing={spacing}"]
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    out = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def main():
    cores = os.cpu_count() or 1
    default_threads = [t for t in (1, 2, 4, 8, 16, 32, 64) if t <= cores]
    if default_threads[-1] != cores:
        default_threads.append(cores)
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--slosh", required=True)
    ap.add_argument("--case", default="seed_3d_dp20mm_dfsph")
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--threads", default=",".join(map(str, default_threads)))
    ap.add_argument("--spacings", default="0.015,0.0125")
    ap.add_argument("--repeat", type=int, default=1)
    a = ap.parse_args()
    threads = [int(t) for t in a.threads.split(",") if t]
    spacings = [float(s) for s in a.spacings.split(",") if s]
    print(
        f"`{a.case}`, first {a.duration:g} s, on {cpu_model()} ({cores} cores), "
        f"{datetime.date.today()}, median of {a.repeat} run(s) each:\n"
    )
    print("| threads | steps | wall s | particle-steps/s | RTF | speed-up | parallel efficiency |")
    print("|---|---|---|---|---|---|---|")
    one = None
    for t in threads:
        r = bench(a.slosh, a.case, a.duration, t, a.repeat)
        if one is None:
            one = (t, r["wall_time_s"])
        speedup = one[1] / r["wall_time_s"] * one[0]
        print(
            f"| {t} | {r['steps']} | {r['wall_time_s']:.2f} | {r['particle_steps_per_s']:.2e} | "
            f"{r['realtime_factor']:.3f} | {speedup:.2f} | {100 * speedup / t:.0f} % |",
            flush=True,
        )
    if spacings:
        t = threads[-1]
        print(f"\nFiner spacings at {t} threads:\n")
        print("| spacing, m | liquid particles | steps | wall s | particle-steps/s | RTF |")
        print("|---|---|---|---|---|---|")
        for s in spacings:
            r = bench(a.slosh, a.case, a.duration, t, a.repeat, s)
            print(
                f"| {s:g} | {r['particles_fluid']} | {r['steps']} | {r['wall_time_s']:.2f} | "
                f"{r['particle_steps_per_s']:.2e} | {r['realtime_factor']:.3f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
