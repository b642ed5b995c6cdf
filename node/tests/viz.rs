//! Seeing a run: `slosh plot` figures, `--snapshots` particle frames read by a third-party VTK reader
//! (meshio), and `slosh render` pictures.

mod common;

use common::{slosh, tmp};
use sph::observe::snapshot::Snapshot;
use std::path::{Path, PathBuf};

/// A small 2D case that moves: the seed tank 0.19 m full at dp = 20 mm, swaying and pitching.
const MOVING: &str = "slosh:
  ros__parameters:
    dimension: 2
    tank: {length: 0.8, breadth: 0.25, height: 0.6}
    fill_height: 0.19
    particle_spacing: 0.02
    probes: {names: [left, mid, right], x: [-0.375, 0.0, 0.375], y: [0.0, 0.0, 0.0]}
    pressure_sensors: {names: [wall_left], x: [-0.4], y: [0.0], z: [0.05]}
    output_rate_hz: 20.0
    duration: 0.6
    motion:
      source: regular
      regular: {amplitude: [0.02, 0, 0, 0, 0.05, 0], period: [0.8, 0, 0, 0, 0.8, 0], phase: [0, 0, 0, 0, 0, 0]}
";

fn run(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let case = dir.join("moving.yaml");
    std::fs::write(&case, MOVING).unwrap();
    let out = dir.join(name);
    let o = slosh()
        .arg("run")
        .arg(&case)
        .arg("--out")
        .arg(&out)
        .args(extra)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// What meshio read from a frame or a series (tests/py/read_vtu.py).
fn meshio(path: &Path) -> serde_json::Value {
    common::py_json(
        "read_vtu.py",
        &[path.as_os_str()],
        &format!("meshio failed on {}", path.display()),
    )
}

fn f64s(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn image(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
}

/// Share of pixels that are not white, and the number of distinct colours.
fn ink(img: &image::RgbImage) -> (f64, usize) {
    let inked = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    let colours: std::collections::HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    (inked as f64 / img.pixels().len() as f64, colours.len())
}

fn plot(dir: &Path, extra: &[&str]) -> std::process::Output {
    slosh()
        .arg("plot")
        .arg(dir)
        .args(extra)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap()
}

/// A run folder with synthetic outputs: probe `a` oscillates with `amplitude` about the 0.19 m fill level.
fn synthetic_run(dir: &Path, amplitude: f64) {
    std::fs::create_dir_all(dir).unwrap();
    let rows = |f: &dyn Fn(f64) -> String| {
        (0..200)
            .map(|i| {
                let t = i as f64 * 0.02;
                format!("{t:.6},{}\n", f(t))
            })
            .collect::<String>()
    };
    let w = |t: f64| (6.0 * t).sin();
    std::fs::write(
        dir.join("probes.csv"),
        "time,a,b\n".to_string()
            + &rows(&|t| format!("{},{}", 0.19 + amplitude * w(t), 0.19 - amplitude * w(t))),
    )
    .unwrap();
    std::fs::write(
        dir.join("wrench.csv"),
        "time,fx,fy,fz,mx,my,mz\n".to_string()
            + &rows(&|t| format!("{},0,{},0,{},0", 20.0 * w(t), -372.0 + w(t), 3.0 * w(t))),
    )
    .unwrap();
    std::fs::write(
        dir.join("pressure.csv"),
        "time,s1\n".to_string() + &rows(&|t| format!("{}", 1800.0 + 100.0 * w(t))),
    )
    .unwrap();
    std::fs::write(
        dir.join("summary.json"),
        r#"{"parameters": {"fill_height": 0.19}}"#,
    )
    .unwrap();
}

#[test]
fn plot_draws_images_of_the_requested_size_that_change_with_the_data() {
    let dir = tmp("plot");
    let (a, b) = (dir.join("a"), dir.join("b"));
    synthetic_run(&a, 0.03);
    synthetic_run(&b, 0.06);
    // A reference of probe a (and a column the run does not have, which is left out with a note).
    let reference = dir.join("measured.csv");
    std::fs::write(
        &reference,
        "time,a,unknown\n0.0,0.19,1\n1.0,0.22,1\n2.0,0.16,1\n3.0,0.2,1\n",
    )
    .unwrap();
    for d in [&a, &b] {
        let o = plot(d, &["--size", "640x480"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    for name in ["probes", "wrench", "pressure"] {
        let (ia, ib) = (
            image(&a.join("plots").join(format!("{name}.png"))),
            image(&b.join("plots").join(format!("{name}.png"))),
        );
        assert_eq!(ia.dimensions(), (640, 480), "{name}");
        let (share, colours) = ink(&ia);
        assert!(
            share > 0.02 && colours > 20,
            "{name}.png looks blank: {share:.3} inked, {colours} colours"
        );
        assert_ne!(ia, ib, "{name}.png did not change with the data");
        let svg = std::fs::read_to_string(a.join("plots").join(format!("{name}.svg"))).unwrap();
        assert!(
            svg.contains("<svg") && svg.contains("width=\"640\"") && svg.contains("height=\"480\""),
            "{name}.svg: {}",
            &svg[..svg.len().min(300)]
        );
        assert!(svg.contains("t (s)"), "{name}.svg has no time axis label");
    }
    let svg = std::fs::read_to_string(a.join("plots/probes.svg")).unwrap();
    assert!(
        svg.contains("fill level 0.19 m") && svg.contains("elevation above the tank bottom (m)")
    );
    assert!(std::fs::read_to_string(a.join("plots/wrench.svg"))
        .unwrap()
        .contains("my (N·m)"));

    // The reference is overlaid (in its own colour, named in the legend) on the probe it names.
    let o = plot(
        &a,
        &[
            "--size",
            "640x480",
            "--reference",
            reference.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("unknown"),
        "the unmatched column is not reported"
    );
    let with_ref = image(&a.join("plots/probes.png"));
    let orange = |img: &image::RgbImage| img.pixels().filter(|p| p.0 == [213, 94, 0]).count();
    assert!(orange(&with_ref) > 100, "no reference line drawn");
    assert_eq!(orange(&image(&b.join("plots/probes.png"))), 0);
    assert!(std::fs::read_to_string(a.join("plots/probes.svg"))
        .unwrap()
        .contains("measured"));
    // A reference whose values all lie between gaps (NaN) is drawn as dots, not left out.
    let sparse = dir.join("sparse.csv");
    std::fs::write(
        &sparse,
        "time,a\n0.0,0.19\n0.5,nan\n1.0,0.22\n1.5,nan\n2.0,0.16\n",
    )
    .unwrap();
    let o = plot(
        &b,
        &["--size", "640x480", "--reference", sparse.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        orange(&image(&b.join("plots/probes.png"))) > 60,
        "the sparse reference is not drawn"
    );
    // The wrench figure has no reference column: unchanged.
    assert_eq!(image(&a.join("plots/wrench.png")), {
        let o = plot(&a, &["--size", "640x480"]);
        assert!(o.status.success());
        image(&a.join("plots/wrench.png"))
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plot_errors_name_the_file_and_the_fix() {
    let dir = tmp("plot-errors");
    synthetic_run(&dir.join("run"), 0.03);
    let bad = dir.join("other.csv");
    std::fs::write(&bad, "time,x,y\n0,1,2\n").unwrap();
    let o = plot(&dir.join("run"), &["--reference", bad.to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        e.contains("other.csv") && e.contains("x, y") && e.contains("probes a, b"),
        "{e}"
    );
    let o = plot(&dir.join("nothing"), &[]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("probes.csv") && e.contains("slosh run"),
        "{e}"
    );
    let o = plot(&dir.join("run"), &["--size", "640"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("WIDTHxHEIGHT"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_frame_reads_back_in_meshio_with_the_values_written() {
    let dir = tmp("vtu-meshio");
    let s = Snapshot {
        time: 0.75,
        dimension: 3,
        fluid: 3,
        position: vec![
            [0.1, 0.2, 0.3],
            [-0.25, 0.125, 0.5],
            [1e-3, -2.5, 7.0],
            [0.4, 0.0, -0.02],
        ],
        velocity: vec![[1.5, -2.0, 0.25], [0.0; 3], [3.0, 4.0, 5.0], [0.0; 3]],
        pressure: vec![1234.5, -10.0, 0.0, 99.25],
        density: vec![1000.0, 1003.5, 998.25, 1000.0],
        id: vec![2, 0, 1, 0],
    };
    let path = dir.join("one.vtu");
    slosh_node::snapshot::vtu::write(&path, &s).unwrap();
    let m = meshio(&path);
    assert_eq!(m["cells"]["vertex"], 4, "{}", m["cells"]);
    let points: Vec<Vec<f64>> = m["points"].as_array().unwrap().iter().map(f64s).collect();
    let want: Vec<Vec<f64>> = s
        .position
        .iter()
        .map(|p| p.iter().map(|&x| x as f64).collect())
        .collect();
    assert_eq!(points, want);
    let vel: Vec<Vec<f64>> = m["point_data"]["velocity"]
        .as_array()
        .unwrap()
        .iter()
        .map(f64s)
        .collect();
    assert_eq!(vel[0], [1.5, -2.0, 0.25]);
    assert_eq!(vel[2], [3.0, 4.0, 5.0]);
    assert_eq!(
        f64s(&m["point_data"]["pressure"]),
        [1234.5, -10.0, 0.0, 99.25]
    );
    assert_eq!(
        f64s(&m["point_data"]["density"]),
        [1000.0, 1003.5, 998.25, 1000.0]
    );
    assert_eq!(f64s(&m["point_data"]["fluid"]), [1.0, 1.0, 1.0, 0.0]);
    assert_eq!(f64s(&m["point_data"]["id"]), [2.0, 0.0, 1.0, 0.0]);
    assert_eq!(m["dtypes"]["fluid"], "uint8");
    assert_eq!(f64s(&m["field_data"]["TimeValue"]), [0.75]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn snapshots_leave_the_outputs_unchanged_read_in_meshio_and_render() {
    let dir = tmp("snapshots");
    let plain = run(&dir, "plain", &[]);
    let snap = run(&dir, "snap", &["--snapshots", "10", "--plot"]);
    // The frames change nothing the run computes.
    for f in ["probes.csv", "wrench.csv", "pressure.csv"] {
        assert_eq!(
            std::fs::read(plain.join(f)).unwrap(),
            std::fs::read(snap.join(f)).unwrap(),
            "{f} differs with snapshots on"
        );
    }
    assert!(snap.join("plots/probes.png").exists() && snap.join("plots/wrench.svg").exists());
    let s = summary(&snap);
    let (nf, nb) = (
        s["particles_fluid"].as_u64().unwrap() as usize,
        s["particles_boundary"].as_u64().unwrap() as usize,
    );
    assert_eq!(
        s["snapshots"]["frames"], 7,
        "0, 0.1, ..., 0.6 s: {}",
        s["snapshots"]
    );
    // The series as meshio (frames) and the XML parser (collection) read it.
    let series = meshio(&snap.join("snapshots/run.pvd"));
    let frames = series.as_array().unwrap();
    assert_eq!(frames.len(), 7);
    for (k, f) in frames.iter().enumerate() {
        let t = f["timestep"].as_f64().unwrap();
        // The state at each 0.1 s (the steps land on the output times, of which these are some).
        assert!((t - 0.1 * k as f64).abs() < 1e-9, "frame {k} at {t}");
        assert!((f64s(&f["field_data"]["TimeValue"])[0] - t).abs() < 1e-9);
        assert_eq!(f["points"].as_array().unwrap().len(), nf + nb);
        let fluid = f64s(&f["point_data"]["fluid"]);
        assert_eq!(fluid.iter().filter(|&&x| x == 1.0).count(), nf);
        let mut ids: Vec<u64> = f64s(&f["point_data"]["id"])[..nf]
            .iter()
            .map(|&x| x as u64)
            .collect();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), nf, "liquid ids are unique");
        let rho = f64s(&f["point_data"]["density"]);
        assert!(rho.iter().all(|r| (900.0..1100.0).contains(r)), "densities");
        // Tank frame: the liquid stays in the tank (x within ±0.4 m, z within 0..0.6 m).
        for p in &f["points"].as_array().unwrap()[..nf] {
            let p = f64s(p);
            assert!(
                p[0].abs() < 0.4 && (0.0..0.6).contains(&p[2]) && p[1] == 0.0,
                "{p:?}"
            );
        }
        // Hydrostatic: the deepest liquid particles are at about ρ g h = 1000 · 9.81 · 0.19 Pa.
        let p_max = f64s(&f["point_data"]["pressure"])[..nf]
            .iter()
            .cloned()
            .fold(f64::MIN, f64::max);
        assert!(
            (1200.0..2500.0).contains(&p_max),
            "frame {k}: largest pressure {p_max}"
        );
    }

    // World frame: the same particles, moved rigidly with the tank.
    let world = run(
        &dir,
        "world",
        &["--snapshots", "10", "--snapshot-frame", "world"],
    );
    let w = meshio(&world.join("snapshots/run.pvd"));
    let (tank_last, world_last) = (&frames[6], &w.as_array().unwrap()[6]);
    let pts = |f: &serde_json::Value| -> Vec<Vec<f64>> {
        f["points"].as_array().unwrap().iter().map(f64s).collect()
    };
    let (a, b) = (pts(tank_last), pts(world_last));
    let moved = a
        .iter()
        .zip(&b)
        .map(|(p, q)| (p[0] - q[0]).abs() + (p[2] - q[2]).abs())
        .fold(0.0, f64::max);
    assert!(
        moved > 1e-3,
        "the world frame equals the tank frame at t = 0.6 s"
    );
    let dist = |p: &[Vec<f64>], i: usize, j: usize| {
        ((p[i][0] - p[j][0]).powi(2) + (p[i][1] - p[j][1]).powi(2) + (p[i][2] - p[j][2]).powi(2))
            .sqrt()
    };
    for (i, j) in [(0, 1), (0, nf - 1), (3, nf + nb - 1), (nf, nf + 5)] {
        assert!(
            (dist(&a, i, j) - dist(&b, i, j)).abs() < 1e-5,
            "distance {i}-{j}: tank {} world {}",
            dist(&a, i, j),
            dist(&b, i, j)
        );
    }

    // Pictures: a PNG per frame and an animated GIF of all frames (a picture an earlier render of more
    // frames left in the folder is removed).
    std::fs::create_dir_all(snap.join("render")).unwrap();
    std::fs::write(snap.join("render/frame_000009.png"), b"stale").unwrap();
    let o = slosh()
        .args(["render"])
        .arg(&snap)
        .args(["--size", "320x240", "--colour", "pressure"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let first = image(&snap.join("render/frame_000000.png"));
    let last = image(&snap.join("render/frame_000006.png"));
    assert_eq!(first.dimensions(), (320, 240));
    assert!(!snap.join("render/frame_000007.png").exists());
    assert!(!snap.join("render/frame_000009.png").exists());
    let (share, colours) = ink(&first);
    assert!(
        share > 0.05 && colours > 10,
        "{share} inked, {colours} colours"
    );
    assert_ne!(
        first, last,
        "the liquid did not move between the first and last picture"
    );
    let mut decoder = gif::DecodeOptions::new();
    decoder.set_color_output(gif::ColorOutput::RGBA);
    let mut gif = decoder
        .read_info(std::fs::File::open(snap.join("render/run.gif")).unwrap())
        .unwrap();
    assert_eq!((gif.width(), gif.height()), (320, 240));
    let mut n = 0;
    while gif.read_next_frame().unwrap().is_some() {
        n += 1;
    }
    assert_eq!(n, 7, "GIF frames");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn render_without_snapshots_says_how_to_make_them() {
    let dir = tmp("render-none");
    synthetic_run(&dir, 0.01);
    let o = slosh()
        .arg("render")
        .arg(&dir)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && e.contains("--snapshots"), "{e}");
    let o = slosh()
        .args([
            "run",
            "dambreak_2d",
            "--duration",
            "0.01",
            "--snapshots",
            "0",
            "--out",
        ])
        .arg(dir.join("zero"))
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("--snapshots") && e.contains("positive"),
        "{e}"
    );
    assert!(!dir.join("zero").exists(), "a refused run left a folder");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_3d_slice_draws_the_layer_nearest_its_y_at_any_spacing() {
    // At dp 40 mm the seed tank's 0.25 m breadth holds 6 rows 41.7 mm apart, at y = ±20.8 mm, ...: none
    // within half a spacing of y = 0.
    let dir = tmp("slice3d");
    let out = dir.join("run");
    let st = slosh()
        .args(["run", "seed_tank_039", "--out"])
        .arg(&out)
        .args(["--duration", "0.05", "--snapshots", "20"])
        .args(["--set", "particle_spacing=0.04"])
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    for y in ["0", "0.1", "-0.125"] {
        let o = slosh()
            .args(["render"])
            .arg(&out)
            .args(["--size", "240x180", "--slice", y, "--out"])
            .arg(dir.join(format!("r{y}")))
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "--slice {y}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let (share, _) = ink(&image(&dir.join(format!("r{y}/frame_000000.png"))));
        assert!(share > 0.05, "--slice {y}: {share} inked");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
