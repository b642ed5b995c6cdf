#!/usr/bin/env python3
"""SPlisHSPlasH against slosh on the seed tank (0.8 x 0.25 m, 0.39 m fill) swayed x = 0.01 sin(2 pi t / 1.2),
both with their incompressible scheme (DFSPH) on two threads, one after the other on this machine.

SPlisHSPlasH: a y-up scene of the same tank (a box mesh, inverted: a container, Akinci et al. 2012 boundary
particles), its liquid one spacing from the walls (closer, the boundary density is over-counted and the first
steps explode), DFSPH with 0.05 % density error, divergence solve on, the CFL variant that also shortens the
step when the iterations grow (2D blows up with plain CFL), steps of at most 5 ms; the tank moved by setting
its velocity every step. The real-time factor is simulated time over the wall time from the first step on
(set-up left out). slosh: `slosh run seed_tank_039` with the same motion; its summary's real-time factor
(the time-stepping loop).

    compare.py --slosh PATH [--seconds 2] [--cases 2d,3d]
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

LENGTH, BREADTH, HEIGHT, FILL = 0.8, 0.25, 0.6, 0.39
AMPLITUDE, PERIOD = 0.01, 1.2
CASES = {"2d": (2, 0.008), "3d": (3, 0.02)}

BOX = """v -0.5 -0.5 0.5
v 0.5 -0.5 0.5
v -0.5 0.5 0.5
v 0.5 0.5 0.5
v -0.5 0.5 -0.5
v 0.5 0.5 -0.5
v -0.5 -0.5 -0.5
v 0.5 -0.5 -0.5
f 1 2 3
f 3 2 4
f 3 4 5
f 5 4 6
f 5 6 7
f 7 6 8
f 7 8 1
f 1 8 2
f 2 8 4
f 4 8 6
f 7 1 5
f 5 1 3
"""


def splishsplash(dim, dp, seconds, work):
    """SPlisHSPlasH's real-time factor, steps and liquid particles on the case."""
    import pysplishsplash as sph

    box = work / "box.obj"
    box.write_text(BOX)
    half = dp
    scene = {
        "Configuration": {
            "sim2D": dim == 2,
            "particleRadius": dp / 2,
            "simulationMethod": 4,
            "gravitation": [0, -9.81, 0],
            "cflMethod": 2,
            "cflFactor": 1,
            "cflMaxTimeStepSize": 0.005,
            "boundaryHandlingMethod": 0,
            "stopAt": seconds,
            "enablePartioExport": False,
            "enableVTKExport": False,
            "DFSPH": {"minIterations": 2, "maxIterations": 100, "maxError": 0.05,
                      "maxIterationsV": 100, "maxErrorV": 0.1, "enableDivergenceSolver": True},
        },
        "Materials": [{"id": "Fluid", "density0": 1000, "viscosityMethod": 0}],
        "RigidBodies": [{
            "geometryFile": str(box),
            "translation": [0, HEIGHT / 2, 0],
            "rotationAxis": [1, 0, 0],
            "rotationAngle": 0,
            "scale": [LENGTH, HEIGHT, BREADTH if dim == 3 else 1.0],
            "isDynamic": False,
            "isWall": True,
            "isAnimated": True,
            "mapInvert": True,
            "mapThickness": 0.0,
            "mapResolution": [40, 30, 15],
        }],
        "FluidBlocks": [{
            "id": "Fluid",
            "denseMode": 0,
            "start": [-LENGTH / 2 + half, half, -BREADTH / 2 + half if dim == 3 else -0.1],
            "end": [LENGTH / 2 - half, FILL, BREADTH / 2 - half if dim == 3 else 0.1],
        }],
    }
    path = work / f"seed_{dim}d.json"
    path.write_text(json.dumps(scene, indent=1))
    clock = {"first": None, "steps": 0, "particles": 0}
    w = 2 * math.pi / PERIOD

    def step():
        sim = sph.Simulation.getCurrent()
        t = sph.TimeManager.getCurrent().getTime()
        if clock["first"] is None:
            clock["first"] = time.perf_counter()
            clock["particles"] = sim.getFluidModel(0).numActiveParticles()
        clock["steps"] += 1
        body = sim.getBoundaryModel(0).getRigidBodyObject()
        body.setVelocity([AMPLITUDE * w * math.cos(w * t), 0, 0])
        body.animate()

    base = sph.Exec.SimulatorBase()
    base.init(useGui=False, sceneFile=str(path), outputDir=str(work / "out"))
    base.setValueFloat(base.STOP_AT, float(seconds))
    base.setTimeStepCB(step)
    base.run()
    wall = time.perf_counter() - clock["first"]
    # (The simulation is gone once run() returns.)
    return seconds / wall, clock["steps"], clock["particles"]


def slosh(exe, dim, dp, seconds, work):
    """slosh's real-time factor, steps and liquid particles on the case."""
    out = work / f"slosh_{dim}d"
    sets = [f"dimension={dim}", f"particle_spacing={dp}", "solver.scheme=dfsph", "motion.source=regular",
            "motion.ramp_time=0.0", f"motion.regular.amplitude=[{AMPLITUDE},0,0,0,0,0]",
            f"motion.regular.period=[{PERIOD},0,0,0,0,0]", "motion.regular.phase=[0,0,0,0,0,0]"]
    cmd = [exe, "run", "seed_tank_039", "--out", str(out), "--duration", str(seconds)]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    s = json.loads((out / "summary.json").read_text())
    return s["realtime_factor"], s["steps"], s["particles_fluid"]


def peer_env():
    """The environment SPlisHSPlasH's module loads in: its wheel bundles libglvnd's GLX and dispatch
    libraries but links the system's libGL, whose GLX then initialises the bundled dispatch library before
    it is loaded and crashes the import; loading the bundled one first avoids that."""
    import glob
    import sysconfig
    env = dict(os.environ)
    libs = Path(sysconfig.get_paths()["purelib"]) / "pysplishsplash.libs"
    found = sorted(glob.glob(str(libs / "libGLdispatch*")))
    if found:
        env["LD_PRELOAD"] = ":".join(filter(None, [found[0], env.get("LD_PRELOAD", "")]))
    return env


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slosh", required=True)
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--cases", default="2d,3d")
    a = ap.parse_args()
    os.environ.setdefault("OMP_NUM_THREADS", "2")
    os.environ.setdefault("RAYON_NUM_THREADS", "2")
    rows = []
    for name in a.cases.split(","):
        dim, dp = CASES[name]
        with tempfile.TemporaryDirectory() as d:
            work = Path(d)
            # Each in a process of its own (SPlisHSPlasH keeps global state between scenes).
            peer = subprocess.run([sys.executable, __file__, "--one", name, "--seconds", str(a.seconds)],
                                  check=True, capture_output=True, text=True, env=peer_env())
            rtf_p, steps_p, n_p = json.loads(peer.stdout.strip().splitlines()[-1])
            rtf_s, steps_s, n_s = slosh(a.slosh, dim, dp, a.seconds, work)
        rows.append((name, dp, n_p, steps_p, rtf_p, n_s, steps_s, rtf_s))
    print(f"seed tank swayed {AMPLITUDE * 1000:.0f} mm at {PERIOD} s, {a.seconds} s simulated, "
          f"OMP_NUM_THREADS={os.environ['OMP_NUM_THREADS']}, RAYON_NUM_THREADS={os.environ['RAYON_NUM_THREADS']}")
    print("| case | dp | SPlisHSPlasH particles / steps / RTF / particle-steps/s | slosh particles / steps / RTF / "
          "particle-steps/s | RTF ratio |")
    print("|---|---|---|---|---|")
    for name, dp, n_p, steps_p, rtf_p, n_s, steps_s, rtf_s in rows:
        ps_p = n_p * steps_p * rtf_p / a.seconds
        ps_s = n_s * steps_s * rtf_s / a.seconds
        print(f"| {name} | {dp * 1000:g} mm | {n_p} / {steps_p} / {rtf_p:.3f} / {ps_p:.3g} | {n_s} / {steps_s} / "
              f"{rtf_s:.3f} / {ps_s:.3g} | {rtf_s / rtf_p:.1f}x |")
    print("(SPlisHSPlasH's liquid starts a spacing from its walls, slosh's half a spacing: it holds fewer "
          "particles for the same tank and fill.)")

if __name__ == "__main__":
    if "--one" in sys.argv:
        i = sys.argv.index("--one")
        name = sys.argv[i + 1]
        seconds = float(sys.argv[sys.argv.index("--seconds") + 1])
        dim, dp = CASES[name]
        with tempfile.TemporaryDirectory() as d:
            print(json.dumps(splishsplash(dim, dp, seconds, Path(d))))
    else:
        main()
