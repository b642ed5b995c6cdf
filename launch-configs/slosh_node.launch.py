"""Start the sloshing node from `ros2 launch`:

    ros2 launch launch-configs/slosh_node.launch.py case:=launch-configs/seed_tank_039.yaml namespace:=/ship1

`slosh` is a plain executable (no colcon package needed), so it is started with ExecuteProcess and the usual
--ros-args. The parameters file is the same one `slosh run` reads. Set `motion:=true` to also start the
synthetic motion publisher (for demos without a ship-motion pipeline).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration


def generate_launch_description():
    case = LaunchConfiguration("case")
    namespace = LaunchConfiguration("namespace")
    node_name = LaunchConfiguration("node_name")
    slosh = LaunchConfiguration("slosh")
    return LaunchDescription(
        [
            DeclareLaunchArgument("case", default_value="launch-configs/seed_tank_039.yaml"),
            DeclareLaunchArgument("namespace", default_value="/"),
            DeclareLaunchArgument("node_name", default_value="slosh"),
            DeclareLaunchArgument("slosh", default_value="slosh", description="path of the slosh binary"),
            DeclareLaunchArgument("motion", default_value="false"),
            ExecuteProcess(
                cmd=[slosh, "node", "--ros-args", "--params-file", case,
                     "-r", ["__ns:=", namespace], "-r", ["__node:=", node_name]],
                output="screen",
            ),
            ExecuteProcess(
                cmd=[slosh, "motion", case, "--duration", "3600", "--wait-for-subscribers", "1",
                     "--ros-args", "-r", ["__ns:=", namespace]],
                output="screen",
                condition=IfCondition(LaunchConfiguration("motion")),
            ),
        ]
    )
