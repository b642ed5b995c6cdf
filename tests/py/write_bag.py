#!/usr/bin/env python3
"""Writes a vessel motion recording with Python rosbags (a third-party rosbag2 writer), as a ship-motion
pipeline or a model test would leave it, for the replay tests.

    write_bag.py MOTION_CSV BAG [--type odom|pose|imu] [--topic NAME] [--start-ns NS] [--log-delay-ns NS]
                 [--zero-stamps] [--duplicate K] [--swap K] [--second-topic NAME] [--chatter]
                 [--bad-schema] [--no-motion] [--storage mcap|sqlite3] [--schema-encoding ENC]

MOTION_CSV has the header ``time,x,y,z,roll,pitch,yaw`` (s, m, rad: the tank frame in a z-up world, the
convention of ``slosh run``). Poses become nav_msgs/Odometry or geometry_msgs/PoseStamped (quaternion from
roll-pitch-yaw, z-y'-x''); ``imu`` writes sensor_msgs/Imu with the orientation, the body angular velocity and
the specific force (acceleration minus gravity, body frame) from finite differences of the samples.
Header stamps are ``start-ns + t``; log times are the stamps plus ``log-delay-ns`` (the recorder's delay).
The options damage the recording on purpose: repeat message K, swap messages K and K+1, zero every header
stamp, add a second motion topic or a std_msgs/String topic, embed a wrong schema for the motion type, or
write only the String topic. ``--schema-encoding`` writes a bare .mcap with the Python ``mcap`` writer instead,
the motion's schema stored under that encoding.
"""

import argparse
import csv
import math

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

G = 9.81


def quaternion(roll, pitch, yaw):
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def rotation(roll, pitch, yaw):
    """Body -> world, R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("bag")
    ap.add_argument("--type", default="odom", choices=["odom", "pose", "imu"])
    ap.add_argument("--topic")
    ap.add_argument("--start-ns", type=int, default=1_700_000_000_000_000_000)
    ap.add_argument("--log-delay-ns", type=int, default=3_000_000)
    ap.add_argument("--zero-stamps", action="store_true")
    ap.add_argument("--duplicate", type=int)
    ap.add_argument("--swap", type=int)
    ap.add_argument("--second-topic")
    ap.add_argument("--chatter", action="store_true")
    ap.add_argument("--bad-schema", action="store_true")
    ap.add_argument("--no-motion", action="store_true")
    ap.add_argument("--storage", default="mcap", choices=["mcap", "sqlite3"])
    ap.add_argument("--schema-encoding")
    a = ap.parse_args()

    with open(a.csv) as f:
        rows = [[float(v) for v in r] for r in list(csv.reader(f))[1:] if r]
    t = np.array([r[0] for r in rows])
    pose = np.array([r[1:] for r in rows])
    ts = get_typestore(Stores.ROS2_JAZZY)
    Time = ts.types["builtin_interfaces/msg/Time"]
    Header = ts.types["std_msgs/msg/Header"]
    Point = ts.types["geometry_msgs/msg/Point"]
    Quat = ts.types["geometry_msgs/msg/Quaternion"]
    Vec3 = ts.types["geometry_msgs/msg/Vector3"]
    Pose = ts.types["geometry_msgs/msg/Pose"]

    kind = {
        "odom": "nav_msgs/msg/Odometry",
        "pose": "geometry_msgs/msg/PoseStamped",
        "imu": "sensor_msgs/msg/Imu",
    }[a.type]
    topic = a.topic or {"odom": "/motion/odom", "pose": "/motion/pose", "imu": "/motion/imu"}[a.type]

    if a.type == "imu":
        # Euler rates -> body angular velocity; position -> acceleration; both by 2nd-order differences.
        d_angles = np.gradient(pose[:, 3:], t, axis=0)
        acc = np.gradient(np.gradient(pose[:, :3], t, axis=0), t, axis=0)

    msgs = []
    for i, ti in enumerate(t):
        stamp_ns = 0 if a.zero_stamps else a.start_ns + int(round(ti * 1e9))
        header = Header(stamp=Time(sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9), frame_id="world")
        x, y, z, roll, pitch, yaw = pose[i]
        q = Quat(*quaternion(roll, pitch, yaw))
        p = Pose(position=Point(x=x, y=y, z=z), orientation=q)
        if a.type == "odom":
            Cov = ts.types["geometry_msgs/msg/PoseWithCovariance"]
            TCov = ts.types["geometry_msgs/msg/TwistWithCovariance"]
            Twist = ts.types["geometry_msgs/msg/Twist"]
            msg = ts.types[kind](
                header=header,
                child_frame_id="base_link",
                pose=Cov(pose=p, covariance=np.zeros(36)),
                twist=TCov(twist=Twist(linear=Vec3(x=0.0, y=0.0, z=0.0), angular=Vec3(x=0.0, y=0.0, z=0.0)),
                           covariance=np.zeros(36)),
            )
        elif a.type == "pose":
            msg = ts.types[kind](header=header, pose=p)
        else:
            dr, dp, dy = d_angles[i]
            w = np.array([
                dr - dy * math.sin(pitch),
                dp * math.cos(roll) + dy * math.cos(pitch) * math.sin(roll),
                dy * math.cos(pitch) * math.cos(roll) - dp * math.sin(roll),
            ])
            f = rotation(roll, pitch, yaw).T @ (acc[i] + np.array([0.0, 0.0, G]))
            msg = ts.types[kind](
                header=header,
                orientation=q,
                orientation_covariance=np.zeros(9),
                angular_velocity=Vec3(x=w[0], y=w[1], z=w[2]),
                angular_velocity_covariance=np.zeros(9),
                linear_acceleration=Vec3(x=f[0], y=f[1], z=f[2]),
                linear_acceleration_covariance=np.zeros(9),
            )
        log_ns = a.start_ns + int(round(ti * 1e9)) + a.log_delay_ns
        msgs.append((log_ns, msg))
    if a.duplicate is not None:
        k = a.duplicate
        msgs.insert(k + 1, (msgs[k][0] + 1000, msgs[k][1]))
    if a.swap is not None:
        k = a.swap
        # Recorded in arrival order: the later stamp arrived first.
        (la, ma), (lb, mb) = msgs[k], msgs[k + 1]
        msgs[k], msgs[k + 1] = (la, mb), (lb, ma)

    if a.schema_encoding:
        from mcap.writer import Writer as McapWriter

        with open(a.bag, "wb") as f:
            w = McapWriter(f)
            w.start(profile="ros2", library="write_bag.py")
            schema = w.register_schema(name=kind, encoding=a.schema_encoding, data=b"")
            channel = w.register_channel(topic=topic, message_encoding="cdr", schema_id=schema)
            for log_ns, msg in msgs:
                w.add_message(channel, log_time=log_ns, data=bytes(ts.serialize_cdr(msg, kind)), publish_time=log_ns)
            w.finish()
        return

    storage = StoragePlugin.MCAP if a.storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(a.bag, version=9, storage_plugin=storage) as w:
        extra = {}
        if a.bad_schema:
            # The motion type's name over another layout (e.g. from an incompatible distribution).
            extra["msgdef"] = "std_msgs/Header header\nfloat64[3] position\n"
            extra["rihs01"] = "RIHS01_" + "0" * 64
        conn = None if a.no_motion else w.add_connection(topic, kind, typestore=ts, **extra)
        second = w.add_connection(a.second_topic, kind, typestore=ts) if a.second_topic else None
        chatter = (
            w.add_connection("/chatter", "std_msgs/msg/String", typestore=ts) if a.chatter or a.no_motion else None
        )
        for log_ns, msg in msgs:
            data = ts.serialize_cdr(msg, kind)
            if conn is not None:
                w.write(conn, log_ns, data)
            if second is not None:
                w.write(second, log_ns + 1, data)
            if chatter is not None:
                s = ts.types["std_msgs/msg/String"](data="hello")
                w.write(chatter, log_ns, ts.serialize_cdr(s, "std_msgs/msg/String"))


if __name__ == "__main__":
    main()
