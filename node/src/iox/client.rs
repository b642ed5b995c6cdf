//! The client side of the coupling service, for a ship-motion solver written in Rust (see
//! `node/examples/couple.rs`): send the vessel's state at t, block until the liquid's answer at t.

use super::*;
use iceoryx2::port::client::Client;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use std::time::{Duration, Instant};

pub struct CouplingClient {
    // Ports before the node: they are dropped first.
    client: Client<ipc::Service, MotionSample, (), StepOutputs, ()>,
    notifier: Notifier<ipc::Service>,
    listener: Listener<ipc::Service>,
    _services: CouplingServices,
    _node: Node<ipc::Service>,
    timeout: Duration,
}

impl CouplingClient {
    /// Opens the coupling service `prefix` (e.g. "slosh"); a step that gets no answer within `timeout`
    /// fails.
    pub fn connect(prefix: &str, timeout: Duration) -> anyhow::Result<Self> {
        let node = node("slosh_coupling_client")?;
        let services = coupling_services(&node, prefix)?;
        Ok(Self {
            client: services.rr.client_builder().create()?,
            notifier: services.request.notifier_builder().create()?,
            listener: services.response.listener_builder().create()?,
            _services: services,
            _node: node,
            timeout,
        })
    }

    /// Whether a server is serving the service now.
    pub fn server_present(&self) -> bool {
        self._services.rr.dynamic_config().number_of_servers() > 0
    }

    /// Waits up to `timeout` for a server.
    pub fn wait_for_server(&self, timeout: Duration) -> anyhow::Result<()> {
        let end = Instant::now() + timeout;
        while !self.server_present() {
            if Instant::now() > end {
                anyhow::bail!("no coupling server within {timeout:?}: start `slosh couple CASE`");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        Ok(())
    }

    /// Sends the vessel's state and waits for the answer. A refused sample comes back with
    /// `status == STATUS_REJECTED` (not an error); no answer in time is an error.
    pub fn step(&self, s: &MotionSample) -> anyhow::Result<StepOutputs> {
        let pending = self.client.send_copy(*s)?;
        self.notifier.notify()?;
        let end = Instant::now() + self.timeout;
        loop {
            if let Some(r) = pending.receive()? {
                return Ok(*r.payload());
            }
            let now = Instant::now();
            if now >= end {
                anyhow::bail!(
                    "no answer to the sample at t = {} s within {:?} (is the coupling server running?)",
                    s.time,
                    self.timeout
                );
            }
            // Events latch: an answer notified before this wait wakes it at once.
            self.listener
                .timed_wait(|_| {}, (end - now).min(Duration::from_millis(50)))?;
        }
    }
}
