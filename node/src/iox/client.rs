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
    /// Answers received for other samples than the one asked (see [`CouplingClient::step`]).
    stale: std::cell::Cell<u64>,
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
            stale: Default::default(),
        })
    }

    /// Answers dropped so far because they were for another sample's time.
    pub fn stale_answers(&self) -> u64 {
        self.stale.get()
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
    ///
    /// Every answer carries its sample's time, and one for another time is dropped: a client killed while
    /// the server worked on its sample leaves that answer on its connection, and iceoryx2 can hand the
    /// connection, answer and all, to the next client that connects (measured: the second sample of the
    /// next client got the dead one's answer).
    pub fn step(&self, s: &MotionSample) -> anyhow::Result<StepOutputs> {
        let pending = self.client.send_copy(*s)?;
        self.notifier.notify()?;
        let end = Instant::now() + self.timeout;
        loop {
            if let Some(r) = pending.receive()? {
                let answer = *r.payload();
                if answer.time.to_bits() == s.time.to_bits() {
                    return Ok(answer);
                }
                self.stale.set(self.stale.get() + 1);
                continue;
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
