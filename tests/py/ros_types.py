"""ROS 2 message types declared for Cyclone DDS's Python IDL, under the DDS type names ROS 2 uses
(``pkg::msg::dds_::Type_``), field order as in the .msg files. Shared by the golden-byte generator
(golden_cdr.py) and the third-party ROS 2 peer (peer_cyclonedds.py)."""

from dataclasses import dataclass

from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t

# --------------------------------------------------------------------------------------------
# Types, declared as ROS 2's rosidl generates them for DDS (field order as in the .msg files).


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: t.int32
    nanosec: t.uint32


@dataclass
class Duration(IdlStruct, typename="builtin_interfaces::msg::dds_::Duration_"):
    sec: t.int32
    nanosec: t.uint32


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: t.float64
    y: t.float64
    z: t.float64


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: t.float64
    y: t.float64
    z: t.float64
    w: t.float64


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point
    orientation: Quaternion


@dataclass
class PoseStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    header: Header
    pose: Pose


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: t.float64
    y: t.float64
    z: t.float64


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3
    angular: Vector3


@dataclass
class TwistStamped(IdlStruct, typename="geometry_msgs::msg::dds_::TwistStamped_"):
    header: Header
    twist: Twist


@dataclass
class Accel(IdlStruct, typename="geometry_msgs::msg::dds_::Accel_"):
    linear: Vector3
    angular: Vector3


@dataclass
class AccelStamped(IdlStruct, typename="geometry_msgs::msg::dds_::AccelStamped_"):
    header: Header
    accel: Accel


@dataclass
class Wrench(IdlStruct, typename="geometry_msgs::msg::dds_::Wrench_"):
    force: Vector3
    torque: Vector3


@dataclass
class WrenchStamped(IdlStruct, typename="geometry_msgs::msg::dds_::WrenchStamped_"):
    header: Header
    wrench: Wrench


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose
    covariance: t.array[t.float64, 36]


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    twist: Twist
    covariance: t.array[t.float64, 36]


@dataclass
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3
    rotation: Quaternion


@dataclass
class TransformStamped(IdlStruct, typename="geometry_msgs::msg::dds_::TransformStamped_"):
    header: Header
    child_frame_id: str
    transform: Transform


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    header: Header
    child_frame_id: str
    pose: PoseWithCovariance
    twist: TwistWithCovariance


@dataclass
class Imu(IdlStruct, typename="sensor_msgs::msg::dds_::Imu_"):
    header: Header
    orientation: Quaternion
    orientation_covariance: t.array[t.float64, 9]
    angular_velocity: Vector3
    angular_velocity_covariance: t.array[t.float64, 9]
    linear_acceleration: Vector3
    linear_acceleration_covariance: t.array[t.float64, 9]


@dataclass
class PointField(IdlStruct, typename="sensor_msgs::msg::dds_::PointField_"):
    name: str
    offset: t.uint32
    datatype: t.uint8
    count: t.uint32


@dataclass
class PointCloud2(IdlStruct, typename="sensor_msgs::msg::dds_::PointCloud2_"):
    header: Header
    height: t.uint32
    width: t.uint32
    fields: t.sequence[PointField]
    is_bigendian: bool
    point_step: t.uint32
    row_step: t.uint32
    data: t.sequence[t.uint8]
    is_dense: bool


@dataclass
class Clock(IdlStruct, typename="rosgraph_msgs::msg::dds_::Clock_"):
    clock: Time


@dataclass
class KeyValue(IdlStruct, typename="diagnostic_msgs::msg::dds_::KeyValue_"):
    key: str
    value: str


@dataclass
class DiagnosticStatus(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticStatus_"):
    level: t.byte  # .msg `byte` is IDL `octet`
    name: str
    message: str
    hardware_id: str
    values: t.sequence[KeyValue]


@dataclass
class DiagnosticArray(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticArray_"):
    header: Header
    status: t.sequence[DiagnosticStatus]


@dataclass
class TFMessage(IdlStruct, typename="tf2_msgs::msg::dds_::TFMessage_"):
    transforms: t.sequence[TransformStamped]


@dataclass
class ProbeArray(IdlStruct, typename="slosh_msgs::msg::dds_::ProbeArray_"):
    header: Header
    names: t.sequence[str]
    positions: t.sequence[Point]
    elevations: t.sequence[t.float64]


@dataclass
class PressureArray(IdlStruct, typename="slosh_msgs::msg::dds_::PressureArray_"):
    header: Header
    names: t.sequence[str]
    positions: t.sequence[Point]
    pressures: t.sequence[t.float64]


@dataclass
class TriggerRequest(IdlStruct, typename="std_srvs::srv::dds_::Trigger_Request_"):
    structure_needs_at_least_one_member: t.uint8


@dataclass
class TriggerResponse(IdlStruct, typename="std_srvs::srv::dds_::Trigger_Response_"):
    success: bool
    message: str


@dataclass
class SetBoolRequest(IdlStruct, typename="std_srvs::srv::dds_::SetBool_Request_"):
    data: bool


@dataclass
class SetBoolResponse(IdlStruct, typename="std_srvs::srv::dds_::SetBool_Response_"):
    success: bool
    message: str


@dataclass
class EmptyRequest(IdlStruct, typename="std_srvs::srv::dds_::Empty_Request_"):
    structure_needs_at_least_one_member: t.uint8


@dataclass
class EmptyResponse(IdlStruct, typename="std_srvs::srv::dds_::Empty_Response_"):
    structure_needs_at_least_one_member: t.uint8


# rcl_interfaces: the parameter services every ROS 2 node serves, and /parameter_events.

@dataclass
class ParameterValue(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterValue_"):
    type: t.uint8
    bool_value: bool
    integer_value: t.int64
    double_value: t.float64
    string_value: str
    byte_array_value: t.sequence[t.uint8]
    bool_array_value: t.sequence[bool]
    integer_array_value: t.sequence[t.int64]
    double_array_value: t.sequence[t.float64]
    string_array_value: t.sequence[str]


@dataclass
class Parameter(IdlStruct, typename="rcl_interfaces::msg::dds_::Parameter_"):
    name: str
    value: ParameterValue


@dataclass
class FloatingPointRange(IdlStruct, typename="rcl_interfaces::msg::dds_::FloatingPointRange_"):
    from_value: t.float64
    to_value: t.float64
    step: t.float64


@dataclass
class IntegerRange(IdlStruct, typename="rcl_interfaces::msg::dds_::IntegerRange_"):
    from_value: t.int64
    to_value: t.int64
    step: t.uint64


@dataclass
class ParameterDescriptor(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterDescriptor_"):
    name: str
    type: t.uint8
    description: str
    additional_constraints: str
    read_only: bool
    dynamic_typing: bool
    floating_point_range: t.sequence[FloatingPointRange, 1]
    integer_range: t.sequence[IntegerRange, 1]


@dataclass
class SetParametersResult(IdlStruct, typename="rcl_interfaces::msg::dds_::SetParametersResult_"):
    successful: bool
    reason: str


@dataclass
class ListParametersResult(IdlStruct, typename="rcl_interfaces::msg::dds_::ListParametersResult_"):
    names: t.sequence[str]
    prefixes: t.sequence[str]


@dataclass
class ParameterEvent(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterEvent_"):
    stamp: Time
    node: str
    new_parameters: t.sequence[Parameter]
    changed_parameters: t.sequence[Parameter]
    deleted_parameters: t.sequence[Parameter]


@dataclass
class ListParametersRequest(IdlStruct, typename="rcl_interfaces::srv::dds_::ListParameters_Request_"):
    prefixes: t.sequence[str]
    depth: t.uint64


@dataclass
class ListParametersResponse(IdlStruct, typename="rcl_interfaces::srv::dds_::ListParameters_Response_"):
    result: ListParametersResult


@dataclass
class GetParametersRequest(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Request_"):
    names: t.sequence[str]


@dataclass
class GetParametersResponse(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Response_"):
    values: t.sequence[ParameterValue]


@dataclass
class GetParameterTypesRequest(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameterTypes_Request_"):
    names: t.sequence[str]


@dataclass
class GetParameterTypesResponse(IdlStruct,
                                typename="rcl_interfaces::srv::dds_::GetParameterTypes_Response_"):
    types: t.sequence[t.uint8]


@dataclass
class DescribeParametersRequest(IdlStruct,
                                typename="rcl_interfaces::srv::dds_::DescribeParameters_Request_"):
    names: t.sequence[str]


@dataclass
class DescribeParametersResponse(IdlStruct,
                                 typename="rcl_interfaces::srv::dds_::DescribeParameters_Response_"):
    descriptors: t.sequence[ParameterDescriptor]


@dataclass
class SetParametersRequest(IdlStruct, typename="rcl_interfaces::srv::dds_::SetParameters_Request_"):
    parameters: t.sequence[Parameter]


@dataclass
class SetParametersResponse(IdlStruct, typename="rcl_interfaces::srv::dds_::SetParameters_Response_"):
    results: t.sequence[SetParametersResult]


@dataclass
class SetParametersAtomicallyRequest(IdlStruct,
                                     typename="rcl_interfaces::srv::dds_::SetParametersAtomically_Request_"):
    parameters: t.sequence[Parameter]


@dataclass
class SetParametersAtomicallyResponse(IdlStruct,
                                      typename="rcl_interfaces::srv::dds_::SetParametersAtomically_Response_"):
    result: SetParametersResult
