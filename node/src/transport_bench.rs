//! `slosh bench-transport`: what moving data costs, without the physics, over iceoryx2 and over DDS on
//! loopback, measured the same way in one process (two threads, two participants or nodes):
//!
//! - coupling round trip: a motion sample out, the outputs back (iceoryx2: the coupling request–response
//!   service with its events, as `slosh couple` serves it; DDS: nav_msgs/Odometry out, geometry_msgs/
//!   WrenchStamped back, reliable);
//! - particle frames: a frame of N particles (position, velocity, pressure, density: 32 bytes each) made
//!   from a snapshot, delivered, read through by the receiver, acknowledged; frames per second with one frame
//!   in flight (iceoryx2: a loaned slice in shared memory; DDS: a sensor_msgs/PointCloud2 of the same
//!   32-byte points).
//!
//! DDS sends discovery traffic: run it inside a loopback-only network namespace (`unshare -rn`, see the
//! manual's iceoryx2 page) unless the machine's network may see it.

use crate::iox::client::CouplingClient;
use crate::iox::{self, Particle, ParticleHeader, StepOutputs};
use futures::executor::block_on;
use iceoryx2::prelude::*;
use ros2_client::qos::{History, WhenFull};
use ros2_client::{MessageTypeName, Name, NodeName, NodeOptions, QosProfile};
use serde::Serialize;
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::geometry_msgs::WrenchStamped;
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::rosgraph_msgs::Clock;
use slosh_msgs::sensor_msgs::{PointCloud2, PointField};
use slosh_msgs::RosMessage;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

#[derive(Debug, Clone)]
pub struct Options {
    /// Round trips timed (after 100 untimed).
    pub round_trips: usize,
    /// Particle counts of the frames timed.
    pub particles: Vec<usize>,
    /// Frames timed per particle count (after 3 untimed).
    pub frames: usize,
    /// Which transports: "iceoryx2", "dds".
    pub transports: Vec<String>,
}

/// Round-trip latency of one coupling step, µs.
#[derive(Debug, Clone, Serialize)]
pub struct Latency {
    pub transport: String,
    pub round_trips: usize,
    pub p50_us: f64,
    pub p90_us: f64,
    pub p99_us: f64,
    pub max_us: f64,
}

/// Particle frames delivered with one in flight.
#[derive(Debug, Clone, Serialize)]
pub struct Throughput {
    pub transport: String,
    pub particles: usize,
    pub bytes_per_frame: usize,
    pub frames: usize,
    pub frames_per_s: f64,
    pub mb_per_s: f64,
    /// Mean delivery time of a frame (made, sent, read through, acknowledged), ms.
    pub ms_per_frame: f64,
}

fn latency(transport: &str, mut us: Vec<f64>) -> Latency {
    us.sort_by(f64::total_cmp);
    let q = |p: f64| us[((us.len() - 1) as f64 * p).round() as usize];
    Latency {
        transport: transport.into(),
        round_trips: us.len(),
        p50_us: q(0.5),
        p90_us: q(0.9),
        p99_us: q(0.99),
        max_us: q(1.0),
    }
}

fn throughput(transport: &str, particles: usize, secs: &[f64]) -> Throughput {
    let total: f64 = secs.iter().sum();
    let bytes = particles * std::mem::size_of::<Particle>();
    Throughput {
        transport: transport.into(),
        particles,
        bytes_per_frame: bytes,
        frames: secs.len(),
        frames_per_s: secs.len() as f64 / total,
        mb_per_s: (bytes * secs.len()) as f64 / total / 1e6,
        ms_per_frame: 1e3 * total / secs.len() as f64,
    }
}

/// A synthetic particle state (what a snapshot holds), changed per frame.
fn particle(i: usize, frame: usize) -> Particle {
    let x = (i % 97) as f32 * 0.01 + frame as f32 * 1e-4;
    Particle {
        position: [x, (i % 13) as f32 * 0.01, (i / 1261) as f32 * 0.01],
        velocity: [0.1, 0.0, -0.05],
        pressure: 1000.0 + i as f32,
        density: 1000.0,
    }
}

/// What a receiver reads through: every particle's x.
fn read_through(p: &[Particle]) -> f32 {
    p.iter().map(|q| q.position[0]).sum()
}

pub fn run(opts: &Options) -> anyhow::Result<(Vec<Latency>, Vec<Throughput>)> {
    if opts.round_trips == 0 || opts.frames == 0 || opts.particles.contains(&0) {
        anyhow::bail!("--round-trips, --frames and every --particles count must be at least 1");
    }
    let (mut lat, mut thr) = (vec![], vec![]);
    for t in &opts.transports {
        match t.as_str() {
            "iceoryx2" => {
                lat.push(latency(t, iox_round_trips(opts.round_trips)?));
                for &n in &opts.particles {
                    thr.push(throughput(t, n, &iox_frames(n, opts.frames)?));
                }
            }
            "dds" => {
                let watchdog = Watchdog::start(Duration::from_secs(
                    120 + opts.round_trips as u64 / 100 + 2 * opts.frames as u64,
                ));
                lat.push(latency(t, dds_round_trips(opts.round_trips)?));
                for &n in &opts.particles {
                    thr.push(throughput(t, n, &dds_frames(n, opts.frames)?));
                }
                watchdog.stop();
            }
            other => anyhow::bail!("--transport {other}: iceoryx2 or dds"),
        }
    }
    Ok((lat, thr))
}

/// Ends the process if DDS stalls (a message lost for good leaves a blocking read waiting).
struct Watchdog(Arc<AtomicBool>);

impl Watchdog {
    fn start(limit: Duration) -> Self {
        let done = Arc::new(AtomicBool::new(false));
        let d = done.clone();
        std::thread::spawn(move || {
            let end = Instant::now() + limit;
            while Instant::now() < end {
                if d.load(Ordering::Relaxed) {
                    return;
                }
                std::thread::sleep(Duration::from_millis(100));
            }
            eprintln!("slosh bench-transport: DDS stalled for {limit:?}; giving up");
            std::process::exit(2);
        });
        Self(done)
    }
    fn stop(self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

fn prefix(what: &str) -> String {
    format!("slosh_bench_{}_{what}", std::process::id())
}

fn iox_round_trips(n: usize) -> anyhow::Result<Vec<f64>> {
    let name = prefix("rt");
    let done = Arc::new(AtomicBool::new(false));
    let (d, nm) = (done.clone(), name.clone());
    let server = std::thread::spawn(move || -> anyhow::Result<()> {
        let node = iox::node("slosh_bench_server")?;
        let svc = iox::coupling_services(&node, &nm)?;
        let server: iox::CouplingServer = svc.rr.server_builder().create()?;
        let listener = svc.request.listener_builder().create()?;
        let notifier = svc.response.notifier_builder().create()?;
        while !d.load(Ordering::Relaxed) {
            listener.timed_wait(|_| {}, Duration::from_millis(20))?;
            while let Some(req) = server.receive()? {
                let answer = StepOutputs {
                    time: req.payload().time,
                    ..Default::default()
                };
                req.send_copy(answer)?;
                notifier.notify()?;
            }
        }
        Ok(())
    });
    let client = CouplingClient::connect(&name, Duration::from_secs(10))?;
    client.wait_for_server(Duration::from_secs(10))?;
    let mut us = Vec::with_capacity(n);
    for i in 0..n + 100 {
        let s = iox::MotionSample {
            time: i as f64,
            orientation: [0.0, 0.0, 0.0, 1.0],
            ..Default::default()
        };
        let t = Instant::now();
        let o = client.step(&s)?;
        let e = t.elapsed().as_secs_f64() * 1e6;
        anyhow::ensure!(
            o.time == s.time,
            "iceoryx2 answered {} to {}",
            o.time,
            s.time
        );
        if i >= 100 {
            us.push(e);
        }
    }
    drop(client);
    done.store(true, Ordering::Relaxed);
    server
        .join()
        .map_err(|_| anyhow::anyhow!("the iceoryx2 echo thread panicked"))??;
    Ok(us)
}

fn iox_frames(particles: usize, frames: usize) -> anyhow::Result<Vec<f64>> {
    let name = prefix(&format!("pf{particles}"));
    let done = Arc::new(AtomicBool::new(false));
    let (d, nm) = (done.clone(), name.clone());
    let ack_name: ServiceName = format!("{name}/ack").as_str().try_into()?;
    let receiver = std::thread::spawn(move || -> anyhow::Result<()> {
        let node = iox::node("slosh_bench_viewer")?;
        let sub = iox::particles_service(&node, &nm)?
            .subscriber_builder()
            .create()?;
        let frame_event = node
            .service_builder(&format!("{nm}/frame").as_str().try_into()?)
            .event()
            .open_or_create()?
            .listener_builder()
            .create()?;
        let ack = node
            .service_builder(&ack_name)
            .event()
            .open_or_create()?
            .notifier_builder()
            .create()?;
        let mut sink = 0.0f32;
        while !d.load(Ordering::Relaxed) {
            frame_event.timed_wait(|_| {}, Duration::from_millis(20))?;
            while let Some(s) = sub.receive()? {
                sink += read_through(s.payload());
                ack.notify()?;
            }
        }
        std::hint::black_box(sink);
        Ok(())
    });
    let node = iox::node("slosh_bench_publisher")?;
    let ports = iox::particles_service(&node, &name)?;
    let publisher = ports
        .publisher_builder()
        .initial_max_slice_len(particles)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()?;
    let frame_event = node
        .service_builder(&format!("{name}/frame").as_str().try_into()?)
        .event()
        .open_or_create()?
        .notifier_builder()
        .create()?;
    let ack = node
        .service_builder(&ack_name)
        .event()
        .open_or_create()?
        .listener_builder()
        .create()?;
    let end = Instant::now() + Duration::from_secs(10);
    while ports.dynamic_config().number_of_subscribers() == 0 {
        anyhow::ensure!(Instant::now() < end, "the iceoryx2 viewer never subscribed");
        std::thread::sleep(Duration::from_millis(5));
    }
    let mut secs = Vec::with_capacity(frames);
    for k in 0..frames + 3 {
        let t = Instant::now();
        let mut sample = publisher.loan_slice_uninit(particles)?;
        *sample.user_header_mut() = ParticleHeader {
            time: k as f64,
            fluid: particles as u64,
            dimension: 3,
            reserved: 0,
        };
        sample.write_from_fn(|i| particle(i, k)).send()?;
        frame_event.notify()?;
        let mut acked = false;
        while !acked {
            anyhow::ensure!(
                t.elapsed() < Duration::from_secs(10),
                "no acknowledgement of iceoryx2 frame {k}"
            );
            ack.timed_wait(|_| acked = true, Duration::from_millis(50))?;
        }
        if k >= 3 {
            secs.push(t.elapsed().as_secs_f64());
        }
    }
    done.store(true, Ordering::Relaxed);
    receiver
        .join()
        .map_err(|_| anyhow::anyhow!("the iceoryx2 viewer thread panicked"))??;
    Ok(secs)
}

/// A DDS participant with one node (no rosout), on the domain of `ROS_DOMAIN_ID`.
fn dds_node(name: &str) -> anyhow::Result<(ros2_client::Context, ros2_client::Node)> {
    let ctx = crate::ros::context()?;
    let node = ctx
        .new_node(
            NodeName::new("/slosh_bench", name).map_err(|e| anyhow::anyhow!("{e:?}"))?,
            NodeOptions::new().enable_rosout(false),
        )
        .map_err(|e| anyhow::anyhow!("cannot create the DDS node: {e:?}"))?;
    Ok((ctx, node))
}

fn qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Wait(Duration::from_millis(200)))
        .history(History::KeepLast { depth: 4 })
}

/// The DDS topic `/slosh_bench/<topic>` of message type `M`.
fn dds_topic<M: RosMessage>(
    node: &mut ros2_client::Node,
    topic: &str,
) -> anyhow::Result<ros2_client::dds::rustdds::Topic> {
    node.create_topic(
        &Name::new("/slosh_bench", topic).map_err(|e| anyhow::anyhow!("{e:?}"))?,
        MessageTypeName::new(M::PACKAGE, M::NAME),
        &qos(),
    )
    .map_err(|e| anyhow::anyhow!("{e:?}"))
}

fn dds_pub<M: RosMessage>(
    node: &mut ros2_client::Node,
    topic: &str,
) -> anyhow::Result<ros2_client::Publisher<M>> {
    let t = dds_topic::<M>(node, topic)?;
    node.create_publisher(&t, Some(qos()))
        .map_err(|e| anyhow::anyhow!("{e:?}"))
}

fn dds_sub<M: RosMessage + 'static>(
    node: &mut ros2_client::Node,
    topic: &str,
) -> anyhow::Result<ros2_client::Subscription<M>> {
    let t = dds_topic::<M>(node, topic)?;
    node.create_subscription(&t, Some(qos()))
        .map_err(|e| anyhow::anyhow!("{e:?}"))
}

/// Waits until `node` sees a reader of `out` and a writer of `back` (discovery), then a little more.
fn matched(node: &ros2_client::Node, out: &str, back: &str) -> anyhow::Result<()> {
    let end = Instant::now() + Duration::from_secs(30);
    while node.subscription_count(&format!("/slosh_bench/{out}")) == 0
        || node.publisher_count(&format!("/slosh_bench/{back}")) == 0
    {
        anyhow::ensure!(
            Instant::now() < end,
            "DDS discovery did not match /slosh_bench/{out} and /{back} within 30 s (is multicast on loopback routed? see docs/src/guide/iceoryx2.md)"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(300));
    Ok(())
}

/// Sends until the first answer comes (reliable writers may drop what precedes matching).
fn first_contact<M: RosMessage + 'static>(
    send: &mut dyn FnMut() -> anyhow::Result<()>,
    sub: &ros2_client::Subscription<M>,
) -> anyhow::Result<()> {
    let end = Instant::now() + Duration::from_secs(30);
    loop {
        send()?;
        let t = Instant::now();
        while t.elapsed() < Duration::from_millis(200) {
            if let Ok(Some(_)) = sub.take() {
                // Drain late answers to earlier tries.
                std::thread::sleep(Duration::from_millis(300));
                while let Ok(Some(_)) = sub.take() {}
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        anyhow::ensure!(Instant::now() < end, "no DDS answer within 30 s");
    }
}

fn dds_round_trips(n: usize) -> anyhow::Result<Vec<f64>> {
    let (_ctx, mut node) = dds_node("client")?;
    let p = dds_pub::<Odometry>(&mut node, "motion")?;
    let s = dds_sub::<WrenchStamped>(&mut node, "wrench")?;
    let echo = std::thread::spawn(move || -> anyhow::Result<()> {
        let (_ctx, mut node) = dds_node("echo")?;
        let s = dds_sub::<Odometry>(&mut node, "motion")?;
        let p = dds_pub::<WrenchStamped>(&mut node, "wrench")?;
        loop {
            let (m, _) = block_on(s.async_take()).map_err(|e| anyhow::anyhow!("{e:?}"))?;
            let stop = m.child_frame_id == "stop";
            let mut w = WrenchStamped::default();
            w.header.stamp = m.header.stamp;
            p.publish(w).map_err(|e| anyhow::anyhow!("{e:?}"))?;
            if stop {
                // Let the last answer be fetched before the participant goes.
                std::thread::sleep(Duration::from_millis(300));
                return Ok(());
            }
        }
    });
    matched(&node, "motion", "wrench")?;
    let odom = |i: usize, stop: bool| {
        let mut m = Odometry::default();
        m.header.stamp = Time::from_secs_f64(i as f64);
        m.header.frame_id = "odom".into();
        m.child_frame_id = if stop { "stop" } else { "base_link" }.into();
        m.pose.pose.orientation.w = 1.0;
        m
    };
    first_contact(
        &mut || {
            p.publish(odom(0, false))
                .map_err(|e| anyhow::anyhow!("{e:?}"))
        },
        &s,
    )?;
    let mut us = Vec::with_capacity(n);
    for i in 1..=n + 100 {
        let t = Instant::now();
        p.publish(odom(i, false))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        loop {
            let (w, _) = block_on(s.async_take()).map_err(|e| anyhow::anyhow!("{e:?}"))?;
            if w.header.stamp == Time::from_secs_f64(i as f64) {
                break;
            }
        }
        if i > 100 {
            us.push(t.elapsed().as_secs_f64() * 1e6);
        }
    }
    p.publish(odom(0, true))
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    echo.join()
        .map_err(|_| anyhow::anyhow!("the DDS echo thread panicked"))??;
    Ok(us)
}

/// A PointCloud2 of the same 32-byte points as [`Particle`].
fn cloud(particles: usize, frame: usize) -> PointCloud2 {
    let mut data = Vec::with_capacity(particles * 32);
    for i in 0..particles {
        let p = particle(i, frame);
        for v in p
            .position
            .iter()
            .chain(&p.velocity)
            .chain([&p.pressure, &p.density])
        {
            data.extend_from_slice(&v.to_le_bytes());
        }
    }
    let mut c = PointCloud2 {
        height: 1,
        width: particles as u32,
        fields: ["x", "y", "z", "vx", "vy", "vz", "pressure", "density"]
            .iter()
            .enumerate()
            .map(|(i, n)| PointField::new(*n, 4 * i as u32, PointField::FLOAT32, 1))
            .collect(),
        is_bigendian: false,
        point_step: 32,
        row_step: 32 * particles as u32,
        data,
        is_dense: true,
        ..Default::default()
    };
    c.header.stamp = Time::from_secs_f64(frame as f64);
    c
}

fn dds_frames(particles: usize, frames: usize) -> anyhow::Result<Vec<f64>> {
    let topic = format!("particles{particles}");
    let ack_topic = format!("ack{particles}");
    let (_ctx, mut node) = dds_node("publisher")?;
    let p = dds_pub::<PointCloud2>(&mut node, &topic)?;
    let s = dds_sub::<Clock>(&mut node, &ack_topic)?;
    let (t2, a2) = (topic.clone(), ack_topic.clone());
    let viewer = std::thread::spawn(move || -> anyhow::Result<()> {
        let (_ctx, mut node) = dds_node("viewer")?;
        let s = dds_sub::<PointCloud2>(&mut node, &t2)?;
        let p = dds_pub::<Clock>(&mut node, &a2)?;
        loop {
            let (c, _) = block_on(s.async_take()).map_err(|e| anyhow::anyhow!("{e:?}"))?;
            let sum: f32 = c
                .data
                .chunks_exact(32)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .sum();
            std::hint::black_box(sum);
            let stop = c.header.frame_id == "stop";
            p.publish(Clock {
                clock: c.header.stamp,
            })
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            if stop {
                std::thread::sleep(Duration::from_millis(300));
                return Ok(());
            }
        }
    });
    matched(&node, &topic, &ack_topic)?;
    first_contact(
        &mut || p.publish(cloud(1, 0)).map_err(|e| anyhow::anyhow!("{e:?}")),
        &s,
    )?;
    let mut secs = Vec::with_capacity(frames);
    for k in 1..=frames + 3 {
        let t = Instant::now();
        p.publish(cloud(particles, k))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        loop {
            let (a, _) = block_on(s.async_take()).map_err(|e| anyhow::anyhow!("{e:?}"))?;
            if a.clock == Time::from_secs_f64(k as f64) {
                break;
            }
        }
        if k > 3 {
            secs.push(t.elapsed().as_secs_f64());
        }
    }
    let mut stop = cloud(1, 0);
    stop.header.frame_id = "stop".into();
    p.publish(stop).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    viewer
        .join()
        .map_err(|_| anyhow::anyhow!("the DDS viewer thread panicked"))??;
    Ok(secs)
}
