//! Zero-copy local transport with iceoryx2 (shared memory, no serialisation): a co-simulation coupling
//! service (motion in, the liquid's wrench, probes and pressures out, one request per coupling step), an
//! outputs service and particle frames, for peers on the same host.
//!
//! Services, under a prefix NAME (`--service`, default `slosh`):
//!
//! | service | pattern | payload |
//! |---|---|---|
//! | `NAME/coupling` | request–response | [`MotionSample`] → [`StepOutputs`] |
//! | `NAME/coupling/request` | event | a client notifies it after sending a request |
//! | `NAME/coupling/response` | event | the server notifies it after answering |
//! | `NAME/outputs` | publish–subscribe | [`StepOutputs`] of every answered step |
//! | `NAME/particles` | publish–subscribe | `[`[`Particle`]`]` with a [`ParticleHeader`] |
//!
//! `SLOSH_IOX_PREFIX` and `SLOSH_IOX_ROOT` set iceoryx2's resource prefix and root folder (tests give every
//! run its own, so runs never meet and leave nothing behind); otherwise iceoryx2's defaults apply.

pub mod client;
pub mod couple;
pub mod motion_pub;
pub mod ports;

pub use crate::input::sample::{check, sample_of, tank_state, Mount};
use iceoryx2::node::Node;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
pub use ports::*;
pub use slosh_msgs::iox::*;

/// iceoryx2's configuration: its defaults, with the prefix and root folder from `SLOSH_IOX_PREFIX` and
/// `SLOSH_IOX_ROOT` when set.
pub fn config() -> anyhow::Result<Config> {
    let mut c = Config::default();
    if let Ok(p) = std::env::var("SLOSH_IOX_PREFIX") {
        c.global.prefix = FileName::new(p.as_bytes()).map_err(|e| {
            anyhow::anyhow!("SLOSH_IOX_PREFIX {p:?}: not a valid file name ({e:?})")
        })?;
    }
    if let Ok(r) = std::env::var("SLOSH_IOX_ROOT") {
        let mut r = r;
        if !r.ends_with('/') {
            r.push('/');
        }
        c.global.set_root_path(
            &Path::new(r.as_bytes())
                .map_err(|e| anyhow::anyhow!("SLOSH_IOX_ROOT {r:?}: not a valid path ({e:?})"))?,
        );
    }
    Ok(c)
}

/// An iceoryx2 node with [`config`], signal handling left to the caller.
pub fn node(name: &str) -> anyhow::Result<Node<ipc::Service>> {
    Ok(NodeBuilder::new()
        .name(&NodeName::new(name).map_err(|e| anyhow::anyhow!("node name {name:?}: {e:?}"))?)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .config(&config()?)
        .create::<ipc::Service>()?)
}

fn service_name(s: &str) -> anyhow::Result<ServiceName> {
    ServiceName::new(s).map_err(|e| anyhow::anyhow!("service name {s:?}: {e:?}"))
}

/// The coupling request–response service and its two event services (request, response), opened or
/// created with the same settings on both sides.
pub struct CouplingServices {
    pub rr: iceoryx2::service::port_factory::request_response::PortFactory<
        ipc::Service,
        MotionSample,
        (),
        StepOutputs,
        (),
    >,
    pub request: iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
    pub response: iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
}

pub fn coupling_services(
    node: &Node<ipc::Service>,
    prefix: &str,
) -> anyhow::Result<CouplingServices> {
    Ok(CouplingServices {
        rr: node
            .service_builder(&service_name(&format!("{prefix}/coupling"))?)
            .request_response::<MotionSample, StepOutputs>()
            .max_active_requests_per_client(2)
            .max_response_buffer_size(2)
            .max_clients(8)
            .max_servers(1)
            .open_or_create()?,
        request: node
            .service_builder(&service_name(&format!("{prefix}/coupling/request"))?)
            .event()
            .open_or_create()?,
        response: node
            .service_builder(&service_name(&format!("{prefix}/coupling/response"))?)
            .event()
            .open_or_create()?,
    })
}

/// The coupling server port type.
pub type CouplingServer = Server<ipc::Service, MotionSample, (), StepOutputs, ()>;
