#!/usr/bin/env python3
"""A ship-motion solver in Python coupled to `slosh couple` step by step over iceoryx2 (pip install
iceoryx2==0.10.0): the barge of `couple.rs`, a mass M on a sway spring k forced by F sin(wt), carrying the
tank. Each step it sends its state at t and blocks for the liquid's force at t, which enters

    M x'' = -k x + F sin(wt) + f_liquid,x(t)

Run `slosh couple CASE` first (same SLOSH_IOX_PREFIX / SLOSH_IOX_ROOT if set), then

    python3 node/examples/couple.py [--service slosh] [--steps 200] [--dt 0.01] [--start 0]

Prints one JSON line per step, as couple.rs does: t, x, the liquid's fx, probe elevations, solver steps.
"""

import argparse
import ctypes
import json
import math
import os
import sys
import struct
import time

import iceoryx2 as iox

MAX_SENSORS = 32
MESSAGE_LEN = 160
STATUS_OK = 0


class MotionSample(ctypes.Structure):
    """slosh::MotionSample (node/src/iox/types.rs): the vessel's state at `time`, SI units, z-up world."""

    _fields_ = [
        ("time", ctypes.c_double),
        ("position", ctypes.c_double * 3),
        ("orientation", ctypes.c_double * 4),  # x, y, z, w (world <- vessel)
        ("velocity", ctypes.c_double * 3),
        ("angular_velocity", ctypes.c_double * 3),  # vessel frame
        ("acceleration", ctypes.c_double * 3),
        ("angular_acceleration", ctypes.c_double * 3),  # vessel frame
    ]

    @staticmethod
    def type_name() -> str:
        return "slosh::MotionSample"


class StepOutputs(ctypes.Structure):
    """slosh::StepOutputs: the liquid at the sample's time (tank frame, about the tank origin)."""

    _fields_ = [
        ("time", ctypes.c_double),
        ("force", ctypes.c_double * 3),
        ("moment", ctypes.c_double * 3),
        ("probes", ctypes.c_double * MAX_SENSORS),
        ("pressures", ctypes.c_double * MAX_SENSORS),
        ("probe_count", ctypes.c_uint32),
        ("pressure_count", ctypes.c_uint32),
        ("status", ctypes.c_uint32),
        ("steps", ctypes.c_uint32),
        ("message", ctypes.c_uint8 * MESSAGE_LEN),
    ]

    @staticmethod
    def type_name() -> str:
        return "slosh::StepOutputs"

    def text(self) -> str:
        return bytes(self.message).split(b"\0", 1)[0].decode("utf-8", "replace")


def config() -> "iox.config.Config":
    """iceoryx2's defaults, with SLOSH_IOX_PREFIX / SLOSH_IOX_ROOT as `slosh` reads them."""
    c = iox.config.default()
    if "SLOSH_IOX_PREFIX" in os.environ:
        c.global_cfg.prefix = iox.FileName.new(os.environ["SLOSH_IOX_PREFIX"])
    if "SLOSH_IOX_ROOT" in os.environ:
        root = os.environ["SLOSH_IOX_ROOT"]
        c.global_cfg.root_path = iox.Path.new(root if root.endswith("/") else root + "/")
    return c


class CouplingClient:
    """Sends a MotionSample on NAME/coupling and waits (on the NAME/coupling/response event) for the answer."""

    def __init__(self, service: str, timeout_s: float = 30.0):
        self.node = (
            iox.NodeBuilder.new()
            .name(iox.NodeName.new("slosh_coupling_client_py"))
            .signal_handling_mode(iox.SignalHandlingMode.Disabled)
            .config(config())
            .create(iox.ServiceType.Ipc)
        )
        # The same settings as the server's (node/src/iox/mod.rs, coupling_services).
        self.rr = (
            self.node.service_builder(iox.ServiceName.new(f"{service}/coupling"))
            .request_response(MotionSample, StepOutputs)
            .max_active_requests_per_client(2)
            .max_response_buffer_size(2)
            .max_clients(8)
            .max_servers(1)
            .open_or_create()
        )
        self.client = self.rr.client_builder().create()
        events = lambda name: (  # noqa: E731
            self.node.service_builder(iox.ServiceName.new(f"{service}/coupling/{name}"))
            .event()
            .open_or_create()
        )
        self.notifier = events("request").notifier_builder().create()
        self.listener = events("response").listener_builder().create()
        self.timeout_s = timeout_s
        end = time.monotonic() + timeout_s
        while self.rr.dynamic_config.number_of_servers == 0:
            if time.monotonic() > end:
                raise TimeoutError(f"no coupling server within {timeout_s} s: start `slosh couple CASE`")
            time.sleep(0.01)

    def step(self, sample: MotionSample) -> StepOutputs:
        pending = self.client.send_copy(sample)
        self.notifier.notify()
        end = time.monotonic() + self.timeout_s
        while True:
            response = pending.receive()
            if response is not None:
                out = StepOutputs()
                ctypes.pointer(out)[0] = response.payload().contents
                # An answer for another time is a dead client's, left on the connection this client got:
                # drop it and wait for ours.
                if struct.pack("<d", out.time) == struct.pack("<d", sample.time):
                    return out
                continue
            if time.monotonic() > end:
                raise TimeoutError(f"no answer to t = {sample.time} s within {self.timeout_s} s")
            self.listener.timed_wait(iox.Duration.from_millis(50))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--service", default="slosh")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--start", type=float, default=0.0)
    a = ap.parse_args()
    client = CouplingClient(a.service)

    # Barge: 2000 kg, sway natural period 1.5 s, forced at 1.2 s (as couple.rs).
    m, w_n, f, w = 2000.0, 2.0 * math.pi / 1.5, 400.0, 2.0 * math.pi / 1.2
    k = m * w_n * w_n
    t, x, v, fx = a.start, 0.0, 0.0, 0.0
    for _ in range(a.steps + 1):
        acc = (-k * x + f * math.sin(w * t) + fx) / m
        s = MotionSample(time=t)
        s.position[0], s.velocity[0], s.acceleration[0] = x, v, acc
        s.orientation[3] = 1.0
        out = client.step(s)
        if out.status != STATUS_OK:
            print(f"the server refused t = {t}: {out.text()}", file=sys.stderr)
            return 1
        fx = out.force[0]
        print(json.dumps({
            "t": round(t, 4), "x": x, "fx": fx,
            "probes": list(out.probes[: out.probe_count]), "steps": out.steps,
        }), flush=True)
        # Semi-implicit Euler with the liquid force of the state at t.
        v += a.dt * acc
        x += a.dt * v
        t += a.dt
    return 0


if __name__ == "__main__":
    sys.exit(main())
