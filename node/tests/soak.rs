//! A soak that loses nothing: `slosh node` in lockstep, recording a bag, driven through `SLOSH_SOAK_SECONDS`
//! (60 in the test command) of motion at 50 Hz by a publisher that injects faults every 20 s of stamps —
//! a burst (25 samples back to back), duplicates (every sample of a second sent twice), reordering (pairs
//! swapped), a jump of the stamps past `input.max_gap_s` (the input on a new time base), the publisher
//! restarted (a new DDS writer) — beside a reliable subscriber of the outputs that never reads, and ended
//! by SIGINT while the node works. Passes when the node exits cleanly; every motion sample it took (accepted
//! or refused) is in the bag, and every output it published; the bag reads with rosbags and mcap; its
//! resident memory is flat after the first fifth of the run. The figures go to stdout. The faults that need
//! the wall clock (input gaps past the timeout, a looped bag's clock) are the second test. The hour:
//!
//!     SLOSH_SOAK_SECONDS=3600 cargo test --release -p slosh-node --test soak -- --nocapture

mod common;

use common::{rest_odometry, ros_topic, slosh, stop_count, Kill};
use ros2_client::qos::{History, WhenFull};
use ros2_client::QosProfile;
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::geometry_msgs::WrenchStamped;
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::rosgraph_msgs::Clock;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const RATE: f64 = 50.0;
const NS: &str = "/soak";
const T0: f64 = 5000.0;
/// Samples the publisher may run ahead of the node's `/clock` (which lags the newest sample by the node's
/// input delay and up to an output period).
const LEAD: f64 = 12.0;

/// A swaying vessel at time `t` (s of motion), stamped `stamp`.
fn odometry(t: f64, stamp: f64) -> Odometry {
    let mut m = rest_odometry(stamp);
    m.pose.pose.position.x = 0.02 * (2.0 * std::f64::consts::PI * t / 1.3).sin();
    m
}

/// Resident memory of process `pid`, kB.
fn rss_kb(pid: u32) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    s.lines()
        .find(|l| l.starts_with("VmRSS:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

#[test]
fn an_hour_of_faulty_motion_loses_nothing() {
    if !common::in_private_netns("an_hour_of_faulty_motion_loses_nothing") {
        return;
    }
    let seconds: f64 = std::env::var("SLOSH_SOAK_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60.0);
    let dir = common::tmp("soak");
    let case = dir.join("case.yaml");
    std::fs::write(&case, common::small_case_at(0.04, "")).unwrap();
    let bag = dir.join("bag");
    let domain = 61u16;
    let mut proc = Kill(
        slosh()
            .args(["node", "--ros-args", "--params-file"])
            .arg(&case)
            .args([
                "-r",
                &format!("__ns:={NS}"),
                "-p",
                "realtime.mode:=lockstep",
            ])
            .args(["-p", "output_rate_hz:=20.0", "-p"])
            .arg(format!("record.path:={}", bag.display()))
            .env("ROS_DOMAIN_ID", domain.to_string())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let pid = proc.0.id();
    // (Read as it comes: over an hour the node's log outgrows a pipe's buffer.)
    let stderr = common::drain_stderr(&mut proc.0);

    let (_ctx, mut node) = common::participant(domain, "soak_driver");
    let odom_qos = QosProfile::publisher_default().history(History::KeepLast { depth: 50 });
    let odom_topic = ros_topic::<Odometry>(&mut node, &format!("{NS}/motion/odom"), &odom_qos);
    let mut publisher = node
        .create_publisher::<Odometry>(&odom_topic, Some(odom_qos.clone()))
        .unwrap();
    let clock_qos = QosProfile::publisher_default().history(History::KeepLast { depth: 1 });
    let clock_topic = ros_topic::<Clock>(&mut node, "/clock", &clock_qos);
    let clock = node
        .create_subscription::<Clock>(&clock_topic, Some(clock_qos))
        .unwrap();
    // A reliable reader of the wrench that never reads: the node must not wait for it.
    let stall_qos = QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Wait(Duration::from_millis(100)))
        .history(History::KeepLast { depth: 1 });
    let stall_topic = ros_topic::<WrenchStamped>(&mut node, &format!("{NS}/wrench"), &stall_qos);
    let _stalled = node
        .create_subscription::<WrenchStamped>(&stall_topic, Some(stall_qos))
        .unwrap();
    common::wait_for_node(
        &node,
        &[&format!("{NS}/motion/odom")],
        &[],
        Duration::from_millis(300),
    );

    // The samples to send: (motion time, stamp), faults included.
    let n = (seconds * RATE) as usize;
    let mut plan: Vec<(f64, f64, bool)> = Vec::with_capacity(n + n / 10);
    let mut jump = 0.0;
    let (mut bursts, mut duplicated, mut swapped, mut jumps, mut restarts) = (0, 0, 0, 0, 0);
    let mut k = 0;
    while k <= n {
        let t = k as f64 / RATE;
        let second = k / RATE as usize;
        let phase = second % 20;
        let first_of_second = k % RATE as usize == 0;
        if phase == 12 && first_of_second {
            // The stamps jump 6 s ahead (past input.max_gap_s = 5 s): a new time base.
            jump += 6.0;
            jumps += 1;
        }
        let stamp = T0 + t + jump;
        match phase {
            6 => {
                plan.push((t, stamp, false));
                plan.push((t, stamp, false));
                duplicated += 1;
            }
            9 if k % 2 == 0 && k < n => {
                let t2 = (k + 1) as f64 / RATE;
                plan.push((t2, T0 + t2 + jump, false));
                plan.push((t, stamp, false));
                swapped += 1;
                k += 1;
            }
            // A burst: this second's first 25 samples go out back to back (no pacing).
            3 if k % RATE as usize == 0 => {
                for j in 0..25 {
                    let tj = (k + j) as f64 / RATE;
                    plan.push((tj, T0 + tj + jump, true));
                }
                bursts += 1;
                k += 24;
            }
            15 if first_of_second => {
                // Marks a restart before this sample (a negative motion time, read below).
                plan.push((-1.0, 0.0, false));
                plan.push((t, stamp, false));
                restarts += 1;
            }
            _ => plan.push((t, stamp, false)),
        }
        k += 1;
    }

    let mut rss: Vec<(f64, u64)> = vec![];
    let start = Instant::now();
    let mut last_rss = Instant::now() - Duration::from_secs(10);
    let mut clock_stamp = f64::NEG_INFINITY;
    let mut sent = 0u64;
    let mut timeouts = 0u64;
    for &(t, stamp, burst) in &plan {
        if t < 0.0 {
            // The publisher restarted: a new writer (a new GUID) on the same topic.
            drop(publisher);
            publisher = node
                .create_publisher::<Odometry>(&odom_topic, Some(odom_qos.clone()))
                .unwrap();
            // (Time for the node's reader to match the new writer.)
            std::thread::sleep(Duration::from_millis(300));
            continue;
        }
        // Lockstep: stay at most LEAD samples ahead of the node's /clock (it reads the stamps of the
        // simulation on the input's time base); a node that rejects the samples does not move it, so the
        // wait is bounded (100 ms).
        if !burst {
            let waited = Instant::now();
            while clock_stamp < stamp - LEAD / RATE && waited.elapsed() < Duration::from_millis(100)
            {
                while let Ok(Some((c, _))) = clock.take() {
                    clock_stamp = c.clock.as_secs_f64();
                }
                std::thread::sleep(Duration::from_micros(200));
            }
            if waited.elapsed() >= Duration::from_millis(100) {
                timeouts += 1;
                if std::env::var("SOAK_DEBUG").is_ok() && timeouts % 20 == 1 {
                    eprintln!("pacing timeout {timeouts} at t {t:.2} stamp {stamp:.2} clock {clock_stamp:.2}");
                }
            }
        }
        publisher.publish(odometry(t, stamp)).unwrap();
        sent += 1;
        if last_rss.elapsed() >= Duration::from_secs(1) {
            last_rss = Instant::now();
            if let Some(kb) = rss_kb(pid) {
                rss.push((start.elapsed().as_secs_f64(), kb));
            }
        }
    }
    // SIGINT while the node is still stepping and writing.
    let (_, accounted) = interrupt_and_account(&mut proc, pid, stderr, &bag, "lockstep");
    let wall = start.elapsed().as_secs_f64();
    let Accounts {
        accepted,
        rejected,
        published,
        odom_in_bag,
        wrench_in_bag,
    } = accounted;
    println!(
        "soak: {seconds} s of motion in {wall:.1} s wall: {sent} samples sent ({bursts} bursts, {duplicated} samples sent twice, {swapped} pairs swapped, {jumps} stamp jumps, {restarts} publisher restarts); the node took {accepted} and refused {rejected}, published {published} outputs; the bag holds {odom_in_bag} motion samples and {wrench_in_bag} wrenches"
    );
    println!("soak: resident memory (s, kB): {rss:?}");
    println!("soak: {timeouts} samples waited the full 100 ms for the node's /clock");
    // The faults were met: duplicates, swapped pairs and the time-base jumps are refused, not lost.
    assert!(rejected >= duplicated as u64, "{rejected} refused");
    assert!(
        accepted + rejected <= sent && accepted > sent * 8 / 10,
        "{accepted} of {sent}"
    );
    assert!(
        published as f64 >= 0.9 * seconds * 20.0,
        "{published} outputs"
    );
    // Memory flat after the first fifth of the run: no more than 10 % (and 4 MB) above its level there.
    let settled = rss
        .iter()
        .find(|(t, _)| *t >= 0.2 * wall)
        .map(|r| r.1)
        .expect("memory samples");
    let peak = rss
        .iter()
        .filter(|(t, _)| *t >= 0.2 * wall)
        .map(|r| r.1)
        .max()
        .unwrap();
    assert!(
        peak as f64 <= settled as f64 * 1.1 + 4096.0,
        "resident memory grew from {settled} kB to {peak} kB: {rss:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The faults that need the wall clock, `SLOSH_SOAK_WALL_SECONDS` (20 in the test command) each: a `realtime`
/// node whose input stops every 5 s for longer than `motion_timeout_s` (it holds the last pose and takes the
/// input back), and a `follow_clock` node fed as by a looped bag (every 8 s `/clock` and the stamps jump
/// back to the start). Passes when the node exits cleanly after SIGINT, every motion sample it took is in
/// the bag (read by rosbags and mcap), every output it published too, and outputs go on after each fault.
#[test]
fn input_gaps_and_a_clock_that_jumps_back_lose_nothing() {
    if !common::in_private_netns("input_gaps_and_a_clock_that_jumps_back_lose_nothing") {
        return;
    }
    let seconds: f64 = std::env::var("SLOSH_SOAK_WALL_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20.0);
    for (mode, domain) in [("realtime", 63u16), ("follow_clock", 64)] {
        let dir = common::tmp(&format!("soak-{mode}"));
        let case = dir.join("case.yaml");
        std::fs::write(&case, common::small_case_at(0.04, "")).unwrap();
        let bag = dir.join("bag");
        let mut proc = Kill(
            slosh()
                .args(["node", "--ros-args", "--params-file"])
                .arg(&case)
                .args(["-r", &format!("__ns:={NS}"), "-p"])
                .arg(format!("realtime.mode:={mode}"))
                .args([
                    "-p",
                    "output_rate_hz:=20.0",
                    "-p",
                    "motion_timeout_s:=0.5",
                    "-p",
                ])
                .arg(format!("record.path:={}", bag.display()))
                .env("ROS_DOMAIN_ID", domain.to_string())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap(),
        );
        let stderr = common::drain_stderr(&mut proc.0);
        let (_ctx, mut node) = common::participant(domain, "soak_driver");
        let qos = QosProfile::publisher_default().history(History::KeepLast { depth: 50 });
        let odom_topic = ros_topic::<Odometry>(&mut node, &format!("{NS}/motion/odom"), &qos);
        let publisher = node
            .create_publisher::<Odometry>(&odom_topic, Some(qos.clone()))
            .unwrap();
        let clock_topic = ros_topic::<Clock>(&mut node, "/clock", &qos);
        let clock = node
            .create_publisher::<Clock>(&clock_topic, Some(qos.clone()))
            .unwrap();
        common::wait_for_node(
            &node,
            &[&format!("{NS}/motion/odom")],
            &[],
            Duration::from_millis(300),
        );
        let start = Instant::now();
        let (mut sent, mut faults) = (0u64, 0u32);
        let mut k = 0u64;
        let mut in_gap = false;
        while start.elapsed().as_secs_f64() < seconds {
            let t = k as f64 / RATE;
            k += 1;
            // Paced by the wall clock.
            let due = Duration::from_secs_f64(t);
            if let Some(wait) = due.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
            let stamp = match mode {
                // Every 5 s the input stops for 1 s (motion_timeout_s is 0.5 s); its stamps go on.
                "realtime" => {
                    let gap = t % 5.0 >= 4.0;
                    if gap && !in_gap {
                        faults += 1;
                    }
                    in_gap = gap;
                    if gap {
                        continue;
                    }
                    T0 + t
                }
                // A looped 8 s bag: /clock and the stamps start again every 8 s.
                _ => {
                    if k > 1 && (k - 1).is_multiple_of(8 * RATE as u64) {
                        faults += 1;
                    }
                    let stamp = T0 + t % 8.0;
                    clock
                        .publish(Clock {
                            clock: Time::from_secs_f64(stamp),
                        })
                        .unwrap();
                    stamp
                }
            };
            publisher.publish(odometry(t, stamp)).unwrap();
            sent += 1;
        }
        std::thread::sleep(Duration::from_millis(300));
        let pid = proc.0.id();
        let (log, accounted) = interrupt_and_account(&mut proc, pid, stderr, &bag, mode);
        let Accounts {
            accepted,
            rejected,
            published,
            odom_in_bag,
            wrench_in_bag,
        } = accounted;
        println!(
            "soak ({mode}): {seconds} s, {sent} samples sent, {faults} faults; the node took {accepted} and refused {rejected}, published {published} outputs; the bag holds {odom_in_bag} motion samples and {wrench_in_bag} wrenches"
        );
        assert!(faults >= 2, "{mode}: {faults} faults");
        assert!(
            accepted + rejected <= sent && accepted > sent / 2,
            "{mode}: {accepted} of {sent}"
        );
        // Outputs go on through the faults: at least half the wall time's worth at 20 Hz.
        assert!(
            published as f64 > 0.5 * 20.0 * seconds,
            "{mode}: {published} outputs\n{log}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// What the node says it took and published (its stop line) and what its bag holds.
struct Accounts {
    accepted: u64,
    rejected: u64,
    published: u64,
    odom_in_bag: u64,
    wrench_in_bag: u64,
}

/// Stops the node `pid` (of `proc`) with SIGINT, asserts that it exits cleanly, and returns its log (read by
/// `stderr`) with the [`accounts`] of the run (`what` names it in a failure).
fn interrupt_and_account(
    proc: &mut Kill,
    pid: u32,
    stderr: std::thread::JoinHandle<String>,
    bag: &std::path::Path,
    what: &str,
) -> (String, Accounts) {
    assert!(Command::new("kill")
        .args(["-INT", &pid.to_string()])
        .status()
        .unwrap()
        .success());
    let log = stderr.join().unwrap();
    let status = proc.0.wait().unwrap();
    assert!(status.success(), "{what}: {status}: {log}");
    let accounted = accounts(&log, bag, what);
    (log, accounted)
}

/// The [`Accounts`] of a run that logged `log` and recorded `bag`; asserts that both third-party readers
/// (rosbags, mcap) find every motion sample the node took, accepted or refused, and every output it
/// published (`what` names the run in a failure).
fn accounts(log: &str, bag: &std::path::Path, what: &str) -> Accounts {
    let (accepted, rejected, published) = (
        stop_count(log, "samples accepted"),
        stop_count(log, "rejected"),
        stop_count(log, "outputs published"),
    );
    let read = common::read_bag(bag);
    let in_bag = |reader: &str, name: &str| {
        read[reader][name]["items"]
            .as_array()
            .map_or(0, |v| v.len() as u64)
    };
    let (odom, wrench) = (format!("{NS}/motion/odom"), format!("{NS}/wrench"));
    for reader in ["rosbags", "mcap"] {
        assert_eq!(
            in_bag(reader, &odom),
            accepted + rejected,
            "{what}, {reader}: motion samples"
        );
        assert_eq!(
            in_bag(reader, &wrench),
            published,
            "{what}, {reader}: wrenches"
        );
    }
    Accounts {
        accepted,
        rejected,
        published,
        odom_in_bag: in_bag("rosbags", &odom),
        wrench_in_bag: in_bag("rosbags", &wrench),
    }
}
