#!/usr/bin/env python3
"""Reads a bag with two third-party readers and prints what each decoded, as JSON:

* rosbags (``rosbags.highlevel.AnyReader``) on the bag folder (or bare .mcap), decoding every message with the
  type definitions embedded in the bag;
* mcap + mcap-ros2-support (``mcap_ros2.reader.read_ros2_messages``) on the .mcap file, plus its metadata
  records.

    read_bag.py BAG_FOLDER_OR_MCAP
"""

import json
import sys
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.reader import read_ros2_messages
from rosbags.highlevel import AnyReader


def summarize(topic, msg):
    """The values the tests compare, per message type."""
    if hasattr(msg, "wrench"):
        f, m = msg.wrench.force, msg.wrench.torque
        return [f.x, f.y, f.z, m.x, m.y, m.z]
    if hasattr(msg, "elevations"):
        return [float(x) for x in msg.elevations]
    if hasattr(msg, "pressures"):
        return [float(x) for x in msg.pressures]
    if hasattr(msg, "status"):
        st = msg.status[0]
        level = st.level[0] if isinstance(st.level, (bytes, bytearray)) else int(st.level)
        return [level, st.message]
    if hasattr(msg, "transforms"):
        return [[t.header.frame_id, t.child_frame_id] for t in msg.transforms]
    if hasattr(msg, "point_step"):
        return [msg.width, msg.height, msg.point_step]
    if hasattr(msg, "pose") and hasattr(msg, "twist"):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        v, w = msg.twist.twist.linear, msg.twist.twist.angular
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        return [p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z, stamp]
    return None


def main():
    path = Path(sys.argv[1])
    mcap_file = path if path.suffix == ".mcap" else next(path.glob("*.mcap"))
    out = {"rosbags": {}, "mcap": {}, "metadata": {}}
    with AnyReader([path]) as reader:
        for conn, t, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            entry = out["rosbags"].setdefault(conn.topic, {"type": conn.msgtype, "items": []})
            entry["items"].append([t * 1e-9, summarize(conn.topic, msg)])
    for m in read_ros2_messages(str(mcap_file)):
        entry = out["mcap"].setdefault(m.channel.topic, {"type": m.schema.name, "items": []})
        entry["items"].append([m.log_time_ns * 1e-9, summarize(m.channel.topic, m.ros_msg)])
    with open(mcap_file, "rb") as f:
        reader = make_reader(f)
        out["profile"] = reader.get_header().profile
        for rec in reader.iter_metadata():
            out["metadata"][rec.name] = dict(rec.metadata)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
