#!/usr/bin/env python3
"""Golden CDR bytes of slosh-msgs' message types, serialized by Cyclone DDS.

Builds one fixed, non-trivial value of every message type of the Rust crate slosh-msgs
(msgs/src) with Cyclone DDS's Python IDL support, declared under the DDS type names ROS 2 uses
(``pkg::msg::dds_::Type_``), and prints a JSON object ``{"pkg/msg/Type": "<hex>", ...}`` of
their serialized forms (encapsulation header + body). ``msgs/tests/golden.rs`` builds the same
values in Rust and checks that ``slosh_msgs::to_cdr`` gives the same bytes and ``from_cdr``
reads them back. Keep the ``value_*`` functions here and the ``value_*`` functions there in
step.

Needs ``cyclonedds==11.0.1`` (tests/py/requirements.txt).

What Cyclone DDS's Python ``IdlStruct.serialize()`` (cyclonedds 11.0.1, cyclonedds/idl/_main.py)
does, found by reading it and checking its output:

* It returns the 4-byte encapsulation header followed by the body. The header is
  ``00 <kind> 00 00``: kind = endianness bit (1 = little) | 0x00 for XCDR1 final/appendable
  types, 0x06 for XCDR2 final (``00 07`` = D_CDR2_LE), 0x08 appendable, 0x0a mutable.
  The two option bytes are always 0 and no trailing padding is appended.
* The endianness defaults to the *host's* (``Endianness.native()``), so it is given explicitly
  as little endian here.
* The version defaults to XCDR1 for plain ``@final`` structs like these (XCDR2 only for types
  whose annotations require it, e.g. ``@appendable``/``@mutable`` or optional members), so the
  header is ``00 01 00 00`` = plain CDR little endian, what ROS 2 (rmw_cyclonedds,
  rmw_fastrtps) sends and ros2 bag stores. ``use_version_2=False`` is passed anyway, and the
  header is asserted.
* Alignment is counted from the start of the body (after the header): the buffer's align
  offset is set to 4 once the header is written. With XCDR1 8-byte values (float64) are
  aligned to 8; XCDR2 would align them to 4 only (``_align_max = 4``), which is not ROS 2's
  layout.
* ``bool`` and ``uint8``/``byte`` are single unaligned bytes; strings are a uint32 length
  including the NUL, the bytes and a NUL; ``sequence[T]`` is a uint32 count and the elements;
  ``array[T, N]`` is the elements only.
"""

import json
import math
import sys
from cyclonedds.idl import Endianness

from ros_types import *  # noqa: F401,F403  (the message types)


# --------------------------------------------------------------------------------------------
# The values: one per type, mirrored by the value_* functions of msgs/tests/golden.rs.
# Strings have lengths that leave the next field unaligned, sequences have 2-3 elements.


def value_time():
    return Time(sec=1712345678, nanosec=987654321)


def value_duration():
    return Duration(sec=-5, nanosec=250000000)


def value_header():
    # "tank" + NUL = 5 bytes: a following float64 needs 7 bytes of padding.
    return Header(stamp=value_time(), frame_id="tank")


def value_point():
    return Point(x=1.5, y=-2.25, z=3.125)


def value_quaternion():
    return Quaternion(x=0.125, y=-0.25, z=0.5, w=0.8)


def value_pose():
    return Pose(position=value_point(), orientation=value_quaternion())


def value_pose_stamped():
    return PoseStamped(header=value_header(), pose=value_pose())


def value_vector3():
    return Vector3(x=0.5, y=-1.5, z=9.81)


def value_twist():
    return Twist(linear=Vector3(x=1.0, y=2.0, z=3.0), angular=Vector3(x=-0.1, y=-0.2, z=-0.3))


def value_twist_stamped():
    return TwistStamped(header=Header(stamp=Time(sec=3, nanosec=7), frame_id="base_link"),
                        twist=value_twist())


def value_accel():
    return Accel(linear=Vector3(x=0.25, y=-9.81, z=4.0), angular=Vector3(x=0.01, y=0.02, z=-0.03))


def value_accel_stamped():
    return AccelStamped(header=Header(stamp=Time(sec=-2, nanosec=999999999), frame_id="imu_link"),
                        accel=value_accel())


def value_wrench():
    return Wrench(force=Vector3(x=12.5, y=-3.0, z=-1530.0), torque=Vector3(x=0.75, y=-221.5, z=1.0))


def value_wrench_stamped():
    return WrenchStamped(header=value_header(), wrench=value_wrench())


def value_pose_with_covariance():
    return PoseWithCovariance(pose=value_pose(), covariance=[float(i) for i in range(36)])


def value_twist_with_covariance():
    return TwistWithCovariance(twist=value_twist(),
                               covariance=[float(i) + 100.0 for i in range(36)])


def value_transform():
    return Transform(translation=Vector3(x=10.0, y=-20.0, z=0.5), rotation=value_quaternion())


def value_transform_stamped():
    return TransformStamped(header=Header(stamp=value_time(), frame_id="world"),
                            child_frame_id="tank", transform=value_transform())


def value_odometry():
    return Odometry(header=Header(stamp=value_time(), frame_id="odom"),
                    child_frame_id="base_link",
                    pose=value_pose_with_covariance(), twist=value_twist_with_covariance())


def value_imu():
    return Imu(header=Header(stamp=value_time(), frame_id="imu"),
               orientation=value_quaternion(),
               orientation_covariance=[float(i) for i in range(9)],
               angular_velocity=Vector3(x=0.01, y=-0.02, z=0.03),
               angular_velocity_covariance=[float(i) + 10.0 for i in range(9)],
               linear_acceleration=Vector3(x=0.1, y=0.2, z=9.81),
               linear_acceleration_covariance=[float(i) + 20.0 for i in range(9)])


def value_point_field():
    return PointField(name="intensity", offset=12, datatype=2, count=1)


def value_point_cloud2():
    # Three points of x, y, z (float32) and intensity (uint8): point_step 13, so data (39
    # bytes) leaves the final bool unaligned.
    return PointCloud2(header=Header(stamp=value_time(), frame_id="lidar"),
                       height=1, width=3,
                       fields=[PointField(name="x", offset=0, datatype=7, count=1),
                               PointField(name="y", offset=4, datatype=7, count=1),
                               PointField(name="z", offset=8, datatype=7, count=1),
                               value_point_field()],
                       is_bigendian=False, point_step=13, row_step=39,
                       data=[(7 * i + 3) % 256 for i in range(39)],
                       is_dense=True)


def value_clock():
    return Clock(clock=Time(sec=42, nanosec=500000000))


def value_key_value():
    return KeyValue(key="particles", value="20000")


def value_diagnostic_status():
    return DiagnosticStatus(level=1, name="slosh: solver", message="real-time factor low",
                            hardware_id="cpu0",
                            values=[value_key_value(), KeyValue(key="rtf", value="0.056")])


def value_diagnostic_array():
    return DiagnosticArray(
        header=Header(stamp=value_time(), frame_id=""),
        status=[value_diagnostic_status(),
                DiagnosticStatus(level=3, name="slosh: ros", message="stale", hardware_id="",
                                 values=[])])


def value_tf_message():
    second = TransformStamped(header=Header(stamp=Time(sec=1, nanosec=2), frame_id="tank"),
                              child_frame_id="liquid_centroid",
                              transform=Transform(translation=Vector3(x=0.0, y=0.1, z=0.2),
                                                  rotation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)))
    return TFMessage(transforms=[value_transform_stamped(), second])


def value_probe_array():
    return ProbeArray(header=value_header(),
                      names=["p1", "centre", "wall_left"],
                      positions=[Point(x=-0.375, y=0.0, z=0.0), Point(x=0.0, y=0.0, z=0.0),
                                 Point(x=0.4, y=0.05, z=0.0)],
                      elevations=[0.391, math.nan, 0.402])


def value_pressure_array():
    return PressureArray(header=value_header(),
                         names=["s1", "bottom"],
                         positions=[Point(x=-0.5, y=0.0, z=0.1), Point(x=0.0, y=0.0, z=0.0)],
                         pressures=[3826.125, 1250.5])


def value_trigger_request():
    return TriggerRequest(structure_needs_at_least_one_member=0)


def value_set_bool_request():
    return SetBoolRequest(data=True)


def value_set_bool_response():
    return SetBoolResponse(success=True, message="paused at t = 1.25 s")


def value_trigger_response():
    return TriggerResponse(success=True, message="reset done")


def value_empty_request():
    return EmptyRequest(structure_needs_at_least_one_member=0)


def value_empty_response():
    return EmptyResponse(structure_needs_at_least_one_member=0)


VALUES = {
    "builtin_interfaces/msg/Time": value_time,
    "builtin_interfaces/msg/Duration": value_duration,
    "std_msgs/msg/Header": value_header,
    "geometry_msgs/msg/Point": value_point,
    "geometry_msgs/msg/Quaternion": value_quaternion,
    "geometry_msgs/msg/Pose": value_pose,
    "geometry_msgs/msg/PoseStamped": value_pose_stamped,
    "geometry_msgs/msg/Vector3": value_vector3,
    "geometry_msgs/msg/Twist": value_twist,
    "geometry_msgs/msg/TwistStamped": value_twist_stamped,
    "geometry_msgs/msg/Accel": value_accel,
    "geometry_msgs/msg/AccelStamped": value_accel_stamped,
    "geometry_msgs/msg/Wrench": value_wrench,
    "geometry_msgs/msg/WrenchStamped": value_wrench_stamped,
    "geometry_msgs/msg/PoseWithCovariance": value_pose_with_covariance,
    "geometry_msgs/msg/TwistWithCovariance": value_twist_with_covariance,
    "geometry_msgs/msg/Transform": value_transform,
    "geometry_msgs/msg/TransformStamped": value_transform_stamped,
    "nav_msgs/msg/Odometry": value_odometry,
    "sensor_msgs/msg/Imu": value_imu,
    "sensor_msgs/msg/PointField": value_point_field,
    "sensor_msgs/msg/PointCloud2": value_point_cloud2,
    "rosgraph_msgs/msg/Clock": value_clock,
    "diagnostic_msgs/msg/KeyValue": value_key_value,
    "diagnostic_msgs/msg/DiagnosticStatus": value_diagnostic_status,
    "diagnostic_msgs/msg/DiagnosticArray": value_diagnostic_array,
    "tf2_msgs/msg/TFMessage": value_tf_message,
    "slosh_msgs/msg/ProbeArray": value_probe_array,
    "slosh_msgs/msg/PressureArray": value_pressure_array,
    "std_srvs/srv/Trigger_Request": value_trigger_request,
    "std_srvs/srv/Trigger_Response": value_trigger_response,
    "std_srvs/srv/SetBool_Request": value_set_bool_request,
    "std_srvs/srv/SetBool_Response": value_set_bool_response,
    "std_srvs/srv/Empty_Request": value_empty_request,
    "std_srvs/srv/Empty_Response": value_empty_response,
}

CDR_LE_HEADER = bytes([0x00, 0x01, 0x00, 0x00])


def main():
    out = {}
    for name, make in VALUES.items():
        value = make()
        data = value.serialize(endianness=Endianness.Little, use_version_2=False)
        if data[:4] != CDR_LE_HEADER:
            sys.exit(f"{name}: unexpected encapsulation header {data[:4].hex()}")
        # The DDS type name must be ROS 2's for the type.
        pkg, kind, typ = name.split("/")
        expected_typename = f"{pkg}::{kind}::dds_::{typ}_"
        if type(value).__idl_typename__.replace(".", "::") != expected_typename:
            sys.exit(f"{name}: declared as {type(value).__idl_typename__}")
        out[name] = data.hex()
    json.dump(out, sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
