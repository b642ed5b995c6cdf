#!/usr/bin/env python3
"""A third-party ROS 2 peer for the node's interoperability test, on Cyclone DDS (the DDS of
rmw_cyclonedds) with ROS 2's DDS naming: topics ``rt/<name>``, types ``pkg::msg::dds_::Type_``.

It waits until the node is on the graph (its first /diagnostics message), then publishes
nav_msgs/Odometry on ``rt/<ns>/motion/odom`` (best effort, as sensor pipelines do) for a tank at
rest at a far-away world position, and receives geometry_msgs/WrenchStamped, slosh_msgs/ProbeArray,
slosh_msgs/PressureArray and diagnostic_msgs/DiagnosticArray (reliable). Prints one JSON object:
counts and the last values received.

    peer_cyclonedds.py --domain 23 --ns /peer --seconds 4 --t0 2000

With ``--parameters NODE`` it also calls the node's rcl_interfaces parameter services (request
``rq/<ns>/<node>/<service>Request``, reply ``rr/<ns>/<node>/<service>Reply``, the enhanced
request/reply mapping): lists, gets, types and describes before the motion, sets ``output_rate_hz`` to
10 Hz halfway through it, and tries an atomic set that includes a read-only parameter; it reads
``/parameter_events`` throughout. The answers go under ``parameters`` in the JSON.
"""

import argparse
import json
import math
import struct
import sys
import time

from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy, Qos
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from ros_types import (DescribeParametersRequest, DescribeParametersResponse, DiagnosticArray,
                       GetParametersRequest, GetParametersResponse, GetParameterTypesRequest,
                       GetParameterTypesResponse, Header, ListParametersRequest, ListParametersResponse,
                       Odometry, Parameter, ParameterEvent, ParameterValue, Point, PointCloud2, Pose,
                       PoseWithCovariance, PressureArray, ProbeArray, Quaternion, SetParametersAtomicallyRequest,
                       SetParametersAtomicallyResponse, SetParametersRequest, SetParametersResponse, Time,
                       Twist, TwistWithCovariance, Vector3, WrenchStamped)


def stamp(t):
    sec = math.floor(t)
    return Time(sec=int(sec), nanosec=int(round((t - sec) * 1e9)) % 1000000000)


def level(v):
    return v[0] if isinstance(v, (bytes, bytearray)) else int(v)


def value(**kw):
    """An rcl_interfaces ParameterValue with the given fields, the rest empty."""
    v = dict(type=0, bool_value=False, integer_value=0, double_value=0.0, string_value="",
             byte_array_value=[], bool_array_value=[], integer_array_value=[], double_array_value=[],
             string_array_value=[])
    v.update(kw)
    return ParameterValue(**v)


def plain(v):
    """A ParameterValue as a JSON-friendly dict of its set field."""
    fields = {1: "bool_value", 2: "integer_value", 3: "double_value", 4: "string_value",
              6: "bool_array_value", 7: "integer_array_value", 8: "double_array_value",
              9: "string_array_value"}
    t = level(v.type)
    got = getattr(v, fields[t]) if t in fields else None
    return {"type": t, "value": list(got) if isinstance(got, (list, tuple)) else got}


class Services:
    """A client of the node's parameter services over plain DDS."""

    def __init__(self, dp, prefix, qos, drain):
        self.dp, self.prefix, self.qos, self.drain = dp, prefix, qos, drain
        self.ends = {}

    def open(self, name, req, resp):
        w = DataWriter(self.dp, Topic(self.dp, f"rq{self.prefix}/{name}Request", req), qos=self.qos)
        r = DataReader(self.dp, Topic(self.dp, f"rr{self.prefix}/{name}Reply", resp), qos=self.qos)
        self.ends[name] = (w, r, resp)

    def call(self, name, request, timeout=15.0):
        w, r, resp = self.ends[name]
        end = time.monotonic() + timeout
        while (w.get_publication_matched_status().current_count == 0
               or r.get_subscription_matched_status().current_count == 0):
            if time.monotonic() > end:
                raise RuntimeError(f"{name}: the node's service never matched")
            self.drain()
            time.sleep(0.02)
        time.sleep(0.2)
        w.write(request)
        while time.monotonic() < end:
            for s in r.take(N=16):
                if isinstance(s, resp):
                    return s
            self.drain()
            time.sleep(0.01)
        raise RuntimeError(f"{name}: no reply")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--ns", default="")
    ap.add_argument("--seconds", type=float, default=4.0, help="seconds of motion to publish")
    ap.add_argument("--rate", type=float, default=50.0)
    ap.add_argument("--t0", type=float, default=2000.0, help="stamp of the first sample")
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--parameters", default="", help="the node's name: call its parameter services")
    a = ap.parse_args()
    ns = a.ns.rstrip("/")

    dp = DomainParticipant(a.domain)
    reliable = Qos(Policy.Reliability.Reliable(duration(milliseconds=200)), Policy.History.KeepLast(200))
    best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(5))
    odom_w = DataWriter(dp, Topic(dp, f"rt{ns}/motion/odom", Odometry), qos=best_effort)
    readers = {
        "wrench": DataReader(dp, Topic(dp, f"rt{ns}/wrench", WrenchStamped), qos=reliable),
        "probes": DataReader(dp, Topic(dp, f"rt{ns}/probes", ProbeArray), qos=reliable),
        "pressures": DataReader(dp, Topic(dp, f"rt{ns}/pressures", PressureArray), qos=reliable),
        "diagnostics": DataReader(dp, Topic(dp, "rt/diagnostics", DiagnosticArray), qos=reliable),
        "particles": DataReader(dp, Topic(dp, f"rt{ns}/particles", PointCloud2), qos=reliable),
    }
    if a.parameters:
        events_qos = Qos(Policy.Reliability.Reliable(duration(milliseconds=200)), Policy.History.KeepLast(1000))
        readers["events"] = DataReader(dp, Topic(dp, "rt/parameter_events", ParameterEvent), qos=events_qos)
    types = {"events": ParameterEvent, "wrench": WrenchStamped, "probes": ProbeArray, "pressures": PressureArray,
             "diagnostics": DiagnosticArray, "particles": PointCloud2}
    got = {k: [] for k in readers}

    def drain():
        for k, r in readers.items():
            for s in r.take(N=256):
                # A writer leaving the graph shows up as an InvalidSample (no data): skip those.
                if isinstance(s, types[k]):
                    got[k].append(s)

    def header_time(h):
        return h.stamp.sec + h.stamp.nanosec * 1e-9 - a.t0

    start = time.monotonic()
    # The node is on the graph once its diagnostics arrive; then give matching a moment.
    while not got["diagnostics"] or odom_w.get_publication_matched_status().current_count == 0:
        drain()
        if time.monotonic() - start > a.timeout:
            print(json.dumps({"error": "the node never appeared (no /diagnostics or no odom reader)"}))
            return 1
        time.sleep(0.02)
    time.sleep(0.3)

    params = {}
    if a.parameters:
        svc = Services(dp, f"{ns}/{a.parameters}",
                       Qos(Policy.Reliability.Reliable(duration(milliseconds=200)), Policy.History.KeepLast(10)),
                       drain)
        svc.open("list_parameters", ListParametersRequest, ListParametersResponse)
        svc.open("get_parameters", GetParametersRequest, GetParametersResponse)
        svc.open("get_parameter_types", GetParameterTypesRequest, GetParameterTypesResponse)
        svc.open("describe_parameters", DescribeParametersRequest, DescribeParametersResponse)
        svc.open("set_parameters", SetParametersRequest, SetParametersResponse)
        svc.open("set_parameters_atomically", SetParametersAtomicallyRequest, SetParametersAtomicallyResponse)
        asked = ["output_rate_hz", "particle_spacing", "solver.scheme", "probes.names", "no_such"]
        listed = svc.call("list_parameters", ListParametersRequest(prefixes=[], depth=0)).result
        solver = svc.call("list_parameters", ListParametersRequest(prefixes=["solver"], depth=1)).result
        vals = svc.call("get_parameters", GetParametersRequest(names=asked)).values
        kinds = svc.call("get_parameter_types", GetParameterTypesRequest(names=asked)).types
        described = svc.call("describe_parameters", DescribeParametersRequest(names=asked[:2])).descriptors
        params = {
            "list": list(listed.names), "prefixes": list(listed.prefixes),
            "solver_depth1": list(solver.names),
            "get": {n: plain(v) for n, v in zip(asked, vals)},
            "types": [level(k) for k in kinds],
            "describe": [{"name": d.name, "type": level(d.type), "read_only": bool(d.read_only),
                          "constraints": d.additional_constraints,
                          "range": [[r.from_value, r.to_value] for r in d.floating_point_range]}
                         for d in described],
        }

    # A tank at rest, 5 km east and 300 m south of the origin, heading 0.3 rad.
    yaw = 0.3
    pose = Pose(position=Point(x=5000.0, y=-300.0, z=2.0),
                orientation=Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)))
    zero = Vector3(x=0.0, y=0.0, z=0.0)
    n = int(round(a.seconds * a.rate))
    t_start = time.monotonic()
    for k in range(n + 1):
        t = k / a.rate
        while time.monotonic() - t_start < t:
            drain()
            time.sleep(0.002)
        if a.parameters and k == n // 2:
            # Halfway: 10 Hz outputs from now on, and a spacing the running node cannot take. The node runs in
            # lockstep behind this input and may lag it on a loaded machine: first wait until its outputs reach
            # within 0.1 s of this sample, so that the set lands at a known point of its time base.
            caught_up = time.monotonic() + a.timeout
            while not got["wrench"] or max(header_time(w.header) for w in got["wrench"]) < t - 0.1:
                if time.monotonic() > caught_up:
                    raise RuntimeError("the node's outputs never caught up with the input before the set")
                drain()
                time.sleep(0.01)
            res = svc.call("set_parameters", SetParametersRequest(parameters=[
                Parameter(name="output_rate_hz", value=value(type=3, double_value=10.0)),
                Parameter(name="particle_spacing", value=value(type=3, double_value=0.01))])).results
            params["set"] = [{"ok": bool(r.successful), "reason": r.reason} for r in res]
            params["set_at"] = t
            res = svc.call("set_parameters_atomically", SetParametersAtomicallyRequest(parameters=[
                Parameter(name="diagnostics_rate_hz", value=value(type=3, double_value=2.0)),
                Parameter(name="dimension", value=value(type=2, integer_value=2))])).result
            params["atomic"] = {"ok": bool(res.successful), "reason": res.reason}
            t_start += time.monotonic() - t_start - t
        odom_w.write(Odometry(
            header=Header(stamp=stamp(a.t0 + t), frame_id="odom"),
            child_frame_id="base_link",
            pose=PoseWithCovariance(pose=pose, covariance=[0.0] * 36),
            twist=TwistWithCovariance(twist=Twist(linear=zero, angular=zero), covariance=[0.0] * 36),
        ))
    end = time.monotonic() + 2.0
    while time.monotonic() < end:
        drain()
        time.sleep(0.02)

    w, p, pr, d = got["wrench"], got["probes"], got["pressures"], got["diagnostics"]
    c = got["particles"]

    def points(cloud):
        """Decodes the cloud by its declared fields (float32 only)."""
        offs = {f.name: f.offset for f in cloud.fields}
        raw = bytes(cloud.data)
        fmt = ">f" if cloud.is_bigendian else "<f"
        return [{k: struct.unpack_from(fmt, raw, i * cloud.point_step + o)[0] for k, o in offs.items()}
                for i in range(cloud.width * cloud.height)]
    if a.parameters:
        params["events"] = [{"node": e.node, "new": [p.name for p in e.new_parameters],
                             "changed": {p.name: plain(p.value) for p in e.changed_parameters}}
                            for e in got["events"]]
    out = {
        "parameters": params,
        "counts": {k: len(v) for k, v in got.items()},
        "wrench_last": None if not w else {
            "t": header_time(w[-1].header), "frame_id": w[-1].header.frame_id,
            "force": [w[-1].wrench.force.x, w[-1].wrench.force.y, w[-1].wrench.force.z],
            "torque": [w[-1].wrench.torque.x, w[-1].wrench.torque.y, w[-1].wrench.torque.z]},
        "wrench_times": [header_time(m.header) for m in w],
        "probes_last": None if not p else {
            "names": list(p[-1].names), "elevations": list(p[-1].elevations),
            "positions": [[q.x, q.y, q.z] for q in p[-1].positions]},
        "pressures_last": None if not pr else {
            "names": list(pr[-1].names), "pressures": list(pr[-1].pressures)},
        "particles_last": None if not c else {
            "width": c[-1].width, "frame_id": c[-1].header.frame_id,
            "fields": [f.name for f in c[-1].fields], "points": points(c[-1])},
        "diagnostics_last": None if not d else {
            "name": d[-1].status[0].name, "level": level(d[-1].status[0].level),
            "message": d[-1].status[0].message,
            "values": {kv.key: kv.value for kv in d[-1].status[0].values}},
    }
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
