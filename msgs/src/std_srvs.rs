//! `std_srvs`: the [`Trigger`], [`SetBool`] and [`Empty`] services.

use serde::{Deserialize, Serialize};

use crate::message::RosService;

/// `std_srvs/srv/Trigger`: a request with no arguments answered by success and a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Trigger;

/// `std_srvs/srv/Trigger_Request`: no fields; ROS 2 gives it a dummy byte.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct TriggerRequest {
    /// Always 0; present because a CDR struct cannot be empty.
    pub structure_needs_at_least_one_member: u8,
}

/// `std_srvs/srv/Trigger_Response`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct TriggerResponse {
    /// Whether the triggered action succeeded.
    pub success: bool,
    /// Informational, e.g. an error message.
    pub message: String,
}

impl RosService for Trigger {
    const PACKAGE: &'static str = "std_srvs";
    const NAME: &'static str = "Trigger";
    const DEFINITION: &'static str = TRIGGER_SRV;
    type Request = TriggerRequest;
    type Response = TriggerResponse;
}

/// `std_srvs/srv/SetBool`: set a boolean state (e.g. pause), answered by success and a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct SetBool;

/// `std_srvs/srv/SetBool_Request`.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct SetBoolRequest {
    /// E.g. for hardware enabling / disabling.
    pub data: bool,
}

/// `std_srvs/srv/SetBool_Response`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct SetBoolResponse {
    /// Whether the call succeeded.
    pub success: bool,
    /// Informational, e.g. an error message.
    pub message: String,
}

impl RosService for SetBool {
    const PACKAGE: &'static str = "std_srvs";
    const NAME: &'static str = "SetBool";
    const DEFINITION: &'static str = SET_BOOL_SRV;
    type Request = SetBoolRequest;
    type Response = SetBoolResponse;
}

/// `std_srvs/srv/Empty`: a request with no arguments and no answer but its arrival.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Empty;

/// `std_srvs/srv/Empty_Request`: no fields; ROS 2 gives it a dummy byte.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct EmptyRequest {
    /// Always 0; present because a CDR struct cannot be empty.
    pub structure_needs_at_least_one_member: u8,
}

/// `std_srvs/srv/Empty_Response`: no fields; ROS 2 gives it a dummy byte.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct EmptyResponse {
    /// Always 0; present because a CDR struct cannot be empty.
    pub structure_needs_at_least_one_member: u8,
}

impl RosService for Empty {
    const PACKAGE: &'static str = "std_srvs";
    const NAME: &'static str = "Empty";
    const DEFINITION: &'static str = EMPTY_SRV;
    type Request = EmptyRequest;
    type Response = EmptyResponse;
}

#[cfg(feature = "ros2-client")]
mod ros2_client_impls {
    use super::{
        EmptyRequest, EmptyResponse, SetBoolRequest, SetBoolResponse, TriggerRequest,
        TriggerResponse,
    };

    impl ros2_client::Message for TriggerRequest {}
    impl ros2_client::Message for TriggerResponse {}
    impl ros2_client::Message for SetBoolRequest {}
    impl ros2_client::Message for SetBoolResponse {}
    impl ros2_client::Message for EmptyRequest {}
    impl ros2_client::Message for EmptyResponse {}
}

// The interface files of ROS 2 Jazzy, verbatim.

const TRIGGER_SRV: &str = r#"---
bool success   # indicate successful run of triggered service
string message # informational, e.g. for error messages
"#;

const SET_BOOL_SRV: &str = r#"bool data # e.g. for hardware enabling / disabling
---
bool success   # indicate successful run of triggered service
string message # informational, e.g. for error messages
"#;

const EMPTY_SRV: &str = r#"---
"#;
