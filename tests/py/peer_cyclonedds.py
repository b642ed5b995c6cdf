#!/usr/bin/env python3
"""A third-party ROS 2 peer for the node's interoperability test, on Cyclone DDS (the DDS of
rmw_cyclonedds) with ROS 2's DDS naming: topics ``rt/<name>``, types ``pkg::msg::dds_::Type_``.

It waits until the node is on the graph (its first /diagnostics message), then publishes
nav_msgs/Odometry on ``rt/<ns>/motion/odom`` (best effort, as sensor pipelines do) for a tank at
rest at a far-away world position, and receives geometry_msgs/WrenchStamped, slosh_msgs/ProbeArray,
slosh_msgs/PressureArray and diagnostic_msgs/DiagnosticArray (reliable). Prints one JSON object:
counts and the last values received.

    peer_cyclonedds.py --domain 23 --ns /peer --seconds 4 --t0 2000
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

from ros_types import (DiagnosticArray, Header, Odometry, Point, PointCloud2, Pose, PoseWithCovariance,
                       PressureArray, ProbeArray, Quaternion, Time, Twist, TwistWithCovariance,
                       Vector3, WrenchStamped)


def stamp(t):
    sec = math.floor(t)
    return Time(sec=int(sec), nanosec=int(round((t - sec) * 1e9)) % 1000000000)


def level(v):
    return v[0] if isinstance(v, (bytes, bytearray)) else int(v)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--ns", default="")
    ap.add_argument("--seconds", type=float, default=4.0, help="seconds of motion to publish")
    ap.add_argument("--rate", type=float, default=50.0)
    ap.add_argument("--t0", type=float, default=2000.0, help="stamp of the first sample")
    ap.add_argument("--timeout", type=float, default=60.0)
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
    types = {"wrench": WrenchStamped, "probes": ProbeArray, "pressures": PressureArray,
             "diagnostics": DiagnosticArray, "particles": PointCloud2}
    got = {k: [] for k in readers}

    def drain():
        for k, r in readers.items():
            for s in r.take(N=256):
                # A writer leaving the graph shows up as an InvalidSample (no data): skip those.
                if isinstance(s, types[k]):
                    got[k].append(s)

    start = time.monotonic()
    # The node is on the graph once its diagnostics arrive; then give matching a moment.
    while not got["diagnostics"] or odom_w.get_publication_matched_status().current_count == 0:
        drain()
        if time.monotonic() - start > a.timeout:
            print(json.dumps({"error": "the node never appeared (no /diagnostics or no odom reader)"}))
            return 1
        time.sleep(0.02)
    time.sleep(0.3)

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

    def t_of(h):
        return h.stamp.sec + h.stamp.nanosec * 1e-9 - a.t0

    w, p, pr, d = got["wrench"], got["probes"], got["pressures"], got["diagnostics"]
    c = got["particles"]

    def points(cloud):
        """Decodes the cloud by its declared fields (float32 only)."""
        offs = {f.name: f.offset for f in cloud.fields}
        raw = bytes(cloud.data)
        fmt = ">f" if cloud.is_bigendian else "<f"
        return [{k: struct.unpack_from(fmt, raw, i * cloud.point_step + o)[0] for k, o in offs.items()}
                for i in range(cloud.width * cloud.height)]
    out = {
        "counts": {k: len(v) for k, v in got.items()},
        "wrench_last": None if not w else {
            "t": t_of(w[-1].header), "frame_id": w[-1].header.frame_id,
            "force": [w[-1].wrench.force.x, w[-1].wrench.force.y, w[-1].wrench.force.z],
            "torque": [w[-1].wrench.torque.x, w[-1].wrench.torque.y, w[-1].wrench.torque.z]},
        "wrench_times": [t_of(m.header) for m in w],
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
