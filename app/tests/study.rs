//! Sweeps, shards, resume, merge, study metrics, the clearance study's trend, and figures.

use clearance_joint::scene::Scene;
use clearance_joint_app::figures::series::{BodySeries, CaseSeries};
use clearance_joint_app::figures::{Figure, FigureKind, decimate_path, minmax_decimate};
use clearance_joint_app::study::metrics::{
    Trend, contact_arc_deg, count_in_windows, last_time_above, max_abs_difference, onset_times,
    path_length,
};
use clearance_joint_app::study::report::Verdict;
use clearance_joint_app::study::sweep::{
    self, ExecOptions, MANIFEST, MetricsTable, Progress, Sweep,
};
use clearance_joint_app::study::{Axis, Grid, Shard};
use clearance_joint_app::study::{StudyOptions, run_studies, select};
use std::collections::BTreeSet;
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cj-study-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn quiet() -> ExecOptions {
    ExecOptions {
        progress: Progress::Quiet,
        ..Default::default()
    }
}

/// A short sweep of the paper's scene: 0.05 s, two clearances (two points).
fn short_sweep(end: &str) -> Sweep {
    Sweep::new(
        "test",
        Scene::solar_panel(),
        vec![
            "run.step=Fixed".into(),
            "run.dt_s=1e-4".into(),
            format!("run.end_s={end}"),
        ],
        Grid::new(vec![Axis::new("hinge.clearance_mm", ["0.25", "0.5"])]).unwrap(),
    )
}

#[test]
fn axis_parsing_keeps_commas_inside_json_values() {
    let a = Axis::parse("hinge.clearance_mm=0.1, 0.25,0.5").unwrap();
    assert_eq!(a.path, "hinge.clearance_mm");
    assert_eq!(a.values, ["0.1", "0.25", "0.5"]);
    let g = Axis::parse("gravity=[0,0,-9.81],[0,0,0]").unwrap();
    assert_eq!(g.values, ["[0,0,-9.81]", "[0,0,0]"]);
    let o = Axis::parse(r#"hinge.contact={"HuntCrossley":{"restitution":0.9}},LiuEtAl"#).unwrap();
    assert_eq!(o.values.len(), 2);
    assert!(Axis::parse("no_values").is_err());
    assert!(Axis::parse("x=1,,2").is_err());
    assert!(Axis::parse("x=[1,2").is_err());
    assert!(Grid::new(vec![Axis::new("a", ["1"]), Axis::new("a", ["2"])]).is_err());
}

#[test]
fn grid_expands_in_nested_loop_order_with_unique_stable_folders() {
    let grid = Grid::new(vec![
        Axis::new("hinge.clearance_mm", ["0.1", "0.25", "0.5"]),
        Axis::new("drive.torque_scale", ["1", "3"]),
        Axis::new("hinge.friction", ["Dry"]),
    ])
    .unwrap();
    assert_eq!(grid.len(), 6);
    let points: Vec<_> = grid.points().collect();
    let seen: Vec<(String, String)> = points
        .iter()
        .map(|p| (p.assignments[0].1.clone(), p.assignments[1].1.clone()))
        .collect();
    let expected = [
        ("0.1", "1"),
        ("0.1", "3"),
        ("0.25", "1"),
        ("0.25", "3"),
        ("0.5", "1"),
        ("0.5", "3"),
    ];
    for (s, e) in seen.iter().zip(expected) {
        assert_eq!((s.0.as_str(), s.1.as_str()), e);
    }
    assert_eq!(
        points[3].dir,
        "003-hinge.clearance_mm=0.25-drive.torque_scale=3"
    );
    assert_eq!(
        points[3].overrides(),
        [
            "hinge.clearance_mm=0.25",
            "drive.torque_scale=3",
            "hinge.friction=Dry"
        ]
    );
    let dirs: BTreeSet<&str> = points.iter().map(|p| p.dir.as_str()).collect();
    assert_eq!(dirs.len(), 6, "folder names are unique");
    assert_eq!(
        grid.points().collect::<Vec<_>>(),
        points,
        "expansion is deterministic"
    );
    assert_eq!(Grid::default().len(), 1, "no axis: the base scene alone");
}

#[test]
fn shards_cover_every_point_exactly_once() {
    let grid = Grid::new(vec![
        Axis::new("a", ["1", "2", "3"]),
        Axis::new("b", ["1", "2", "3"]),
    ])
    .unwrap();
    for n in 1..=11 {
        let mut count = vec![0; grid.len()];
        for k in 0..n {
            let shard = Shard::new(k, n).unwrap();
            for p in shard.points(&grid) {
                assert!(shard.contains(p.index));
                count[p.index] += 1;
            }
            assert_eq!(shard.len(&grid), shard.points(&grid).count());
        }
        assert!(count.iter().all(|&c| c == 1), "n = {n}: {count:?}");
    }
    assert_eq!(Shard::parse("2/4").unwrap(), Shard::new(2, 4).unwrap());
    for bad in ["4/4", "1", "a/2", "0/0", "-1/2"] {
        assert!(Shard::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn resume_reuses_finished_points_and_redoes_half_written_ones() {
    let out = scratch("resume");
    let sweep = short_sweep("0.05");
    let first = sweep.run(&out, Shard::ALL, quiet()).unwrap();
    assert_eq!(first.points.len(), 2);
    assert!(first.points.iter().all(|p| !p.reused));
    assert!(first.table.failures.is_empty());
    for p in &first.points {
        for f in ["ideal.csv", "clearance.csv", "summary.json", MANIFEST] {
            assert!(p.dir.join(f).is_file(), "{}/{f}", p.dir.display());
        }
    }
    assert!(out.join("metrics.csv").is_file() && out.join("metrics.json").is_file());

    // Rerun: both reused, same metrics (including the stored wall time).
    let second = sweep.run(&out, Shard::ALL, quiet()).unwrap();
    assert!(second.points.iter().all(|p| p.reused));
    assert_eq!(first.table.rows, second.table.rows);

    // Half-written point 0: result files present, manifest missing (killed before it was written).
    std::fs::remove_file(first.points[0].dir.join(MANIFEST)).unwrap();
    // Half-written point 1: a CSV cut short after the manifest was written.
    let csv = first.points[1].dir.join("clearance.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    std::fs::write(&csv, &text[..text.len() / 2]).unwrap();
    let third = sweep.run(&out, Shard::ALL, quiet()).unwrap();
    assert!(
        third.points.iter().all(|p| !p.reused),
        "both half-written points are redone"
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), text, "whole again");
    let strip = |t: &MetricsTable| {
        t.rows
            .iter()
            .map(|r| {
                let mut m = r.metrics.clone();
                m.wall_s = 0.0;
                m
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(strip(&first.table), strip(&third.table), "deterministic");

    // A changed scene (another end time) is not the finished point: it reruns.
    let longer = short_sweep("0.06").run(&out, Shard::ALL, quiet()).unwrap();
    assert!(longer.points.iter().all(|p| !p.reused));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn sharded_sweep_merges_into_the_unsharded_table() {
    let out = scratch("shards");
    let sweep = Sweep::new(
        "test",
        Scene::solar_panel(),
        vec![
            "run.step=Fixed".into(),
            "run.dt_s=1e-4".into(),
            "run.end_s=0.03".into(),
        ],
        Grid::new(vec![Axis::new(
            "hinge.clearance_mm",
            ["0.1", "0.25", "0.5"],
        )])
        .unwrap(),
    );
    let a = sweep.run(&out, Shard::new(0, 2).unwrap(), quiet()).unwrap();
    let b = sweep.run(&out, Shard::new(1, 2).unwrap(), quiet()).unwrap();
    assert_eq!(a.points.len() + b.points.len(), 3);
    let tables = sweep::shard_tables_in(&out).unwrap();
    assert_eq!(tables.len(), 2);
    let loaded: Vec<MetricsTable> = tables
        .iter()
        .map(|p| MetricsTable::load(p).unwrap())
        .collect();
    let merged = sweep::merge(&loaded).unwrap();
    assert!(merged.missing.is_empty() && merged.failures.is_empty());
    let indices: Vec<usize> = merged.rows.iter().map(|r| r.point.index).collect();
    assert_eq!(indices, [0, 1, 2]);

    // The whole grid in one go reuses the shards' points and gives the same table rows.
    let whole = sweep.run(&out, Shard::ALL, quiet()).unwrap();
    assert!(whole.points.iter().all(|p| p.reused));
    assert_eq!(whole.table.rows, merged.rows);

    // One shard alone: the other's points are reported missing.
    let partial = sweep::merge(&loaded[..1]).unwrap();
    assert_eq!(partial.missing, [1]);
    // Tables of another sweep are refused.
    let mut other = loaded[1].clone();
    other.sweep.points = 4;
    assert!(sweep::merge(&[loaded[0].clone(), other]).is_err());

    // The merged CSV: one header and a row per point, the axis value in its own column.
    let csv = merged.to_csv().unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 4);
    assert!(lines[0].starts_with("index,dir,hinge.clearance_mm,dt_s,"));
    assert!(
        lines[0].contains("hinge_onsets")
            && lines[0].contains("hinge_separated_impacts")
            && lines[0].contains("panel_rate_dev_rms_deg_s")
    );
    assert!(!csv.contains("NaN") && !csv.contains("inf"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_bad_sweep_value_fails_before_anything_runs() {
    let out = scratch("bad");
    let sweep = Sweep::new(
        "test",
        Scene::solar_panel(),
        vec!["run.end_s=0.01".into()],
        Grid::new(vec![Axis::new("hinge.clearance_mm", ["0.25", "-1"])]).unwrap(),
    );
    let err = sweep
        .run(&out, Shard::ALL, quiet())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("clearance_mm") && err.contains("001-"),
        "{err}"
    );
    assert!(!out.join("points").exists(), "nothing ran");
    // A point that fails while running is listed, the others finish.
    let unstable = Sweep::new(
        "test",
        Scene::solar_panel(),
        vec![
            "run.contact_integration=Explicit".into(),
            "run.step=Fixed".into(),
            "run.end_s=0.1".into(),
        ],
        // 2e-4 s is beyond the explicit first impact's stability limit (about 1.1e-4 s): refused.
        Grid::new(vec![Axis::new("run.dt_s", ["5e-5", "2e-4"])]).unwrap(),
    );
    let outcome = unstable.run(&out, Shard::ALL, quiet()).unwrap();
    assert_eq!(outcome.points.len(), 1);
    assert_eq!(outcome.table.failures.len(), 1);
    assert!(
        outcome.table.failures[0].error.contains("run.dt_s"),
        "{}",
        outcome.table.failures[0].error
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn metrics_of_hand_made_series() {
    let t = [0.0, 0.1, 0.2, 0.3, 0.4];
    assert_eq!(last_time_above(&t, &[0.0, 5.0, 1.0, 3.0, 0.5], 2.0), 0.3);
    assert_eq!(last_time_above(&t, &[0.0; 5], 2.0), 0.0);
    assert_eq!(max_abs_difference(&[1.0, 2.0, 3.0], &[1.5, 0.0, 3.0]), 2.0);
    // A unit square walked once: perimeter 4.
    assert!(
        (path_length(&[0.0, 1.0, 1.0, 0.0, 0.0], &[0.0, 0.0, 1.0, 1.0, 0.0]) - 4.0).abs() < 1e-12
    );
    // Contacts at 0 and 90 degrees: a quarter of the circle; at 0, 120, 240: two thirds;
    // across the +-180 wrap (170, -170): 20; free flight points are ignored.
    let d = |a: f64| (a.to_radians().cos(), a.to_radians().sin());
    let arc = |angles: &[f64], contact: &[f64]| {
        let (u, v): (Vec<f64>, Vec<f64>) = angles.iter().map(|&a| d(a)).unzip();
        contact_arc_deg(&u, &v, contact)
    };
    assert!((arc(&[0.0, 90.0, 45.0], &[1.0, 1.0, 0.0]) - 90.0).abs() < 1e-9);
    assert!((arc(&[0.0, 120.0, 240.0], &[1.0; 3]) - 240.0).abs() < 1e-9);
    assert!((arc(&[170.0, -170.0], &[1.0; 2]) - 20.0).abs() < 1e-9);
    assert_eq!(arc(&[10.0], &[1.0]), 0.0);
    // Onsets: contact turning on at 0.1 and 0.4 (and at the first sample in the second case).
    assert_eq!(onset_times(&t, &[0.0, 1.0, 1.0, 0.0, 1.0]), [0.1, 0.4]);
    assert_eq!(onset_times(&t, &[1.0, 0.0, 0.0, 0.0, 0.0]), [0.0]);
    assert_eq!(
        count_in_windows(&[0.1, 0.4, 1.2, 2.5, 9.0], 1.0, 3),
        [2, 1, 2]
    );
    assert_eq!(Trend::of(&[1.0, 2.0, 3.0], 0.0), Trend::Increasing);
    assert_eq!(Trend::of(&[3.0, 2.0, 1.0], 0.0), Trend::Decreasing);
    assert_eq!(Trend::of(&[1.0, 3.0, 2.0], 0.0), Trend::Mixed);
    assert_eq!(Trend::of(&[1.0, 1.001, 0.999], 0.01), Trend::Flat);
}

#[test]
fn decimation_keeps_peaks_and_paths() {
    let n = 100_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let mut y: Vec<f64> = t.iter().map(|x| x.sin()).collect();
    y[12_345] = 500.0; // an impact one sample wide
    y[54_321] = -7.0;
    let d = minmax_decimate(&t, &y, 0.0, t[n - 1], 800);
    assert!(d.len() <= 1600, "{}", d.len());
    assert!(d.contains(&(t[12_345], 500.0)) && d.contains(&(t[54_321], -7.0)));
    assert!(d.windows(2).all(|w| w[0].0 <= w[1].0), "time order");
    // A circle of 10,000 points at 1e-3 spacing kept at 0.01: about a tenth, ends kept.
    let (u, v): (Vec<f64>, Vec<f64>) = (0..10_000)
        .map(|i| {
            let a = i as f64 * 1e-3;
            (a.cos(), a.sin())
        })
        .unzip();
    let p = decimate_path(&u, &v, 0.01);
    assert!(p.len() > 900 && p.len() < 1100, "{}", p.len());
    assert_eq!(p[0], (u[0], v[0]));
    assert_eq!(*p.last().unwrap(), (u[9_999], v[9_999]));
}

fn synthetic_case(label: &str, c: f64, phase: f64) -> CaseSeries {
    let n = 400;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.005).collect();
    let angle: Vec<f64> = t.iter().map(|x| 2.0 * x * x).collect();
    let rate: Vec<f64> = t.iter().map(|x| 4.0 * x).collect();
    let wobble: Vec<f64> = t
        .iter()
        .map(|x| 4.0 * x + (40.0 * x + phase).sin())
        .collect();
    let force: Vec<f64> = (0..n)
        .map(|i| if i % 50 == 7 { 100.0 * c } else { 0.0 })
        .collect();
    let (u, v): (Vec<f64>, Vec<f64>) = t
        .iter()
        .map(|x| {
            let r = c * (x / 2.0).min(1.0);
            (r * (3.0 * x + phase).cos(), r * (3.0 * x + phase).sin())
        })
        .unzip();
    CaseSeries {
        label: label.into(),
        hinge: "hinge".into(),
        clearance_mm: c,
        t_s: t.clone(),
        bodies: vec![
            BodySeries {
                name: "panel".into(),
                angle_deg: angle.clone(),
                rate_deg_s: wobble,
                angle_ideal_deg: angle.clone(),
                rate_ideal_deg_s: rate.clone(),
            },
            BodySeries {
                name: "satellite".into(),
                angle_deg: angle.iter().map(|a| -0.01 * a).collect(),
                rate_deg_s: rate.iter().map(|a| -0.01 * a).collect(),
                angle_ideal_deg: angle.iter().map(|a| -0.01 * a).collect(),
                rate_ideal_deg_s: rate.iter().map(|a| -0.01 * a).collect(),
            },
        ],
        force_n: force,
        force_ideal_n: t.iter().map(|x| 0.25 + 0.01 * x).collect(),
        contact: u
            .iter()
            .zip(&v)
            .map(|(a, b)| if a.hypot(*b) >= c * 0.999 { 1.0 } else { 0.0 })
            .collect(),
        ecc_u_mm: u,
        ecc_v_mm: v,
        peaks: Vec::new(),
    }
}

/// Width and height from a PNG's IHDR chunk, after checking the signature.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(bytes.len() > 1000, "PNG of {} bytes", bytes.len());
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

#[test]
fn figures_render_to_valid_png_and_svg_files() {
    let out = scratch("plots");
    let cases = [
        synthetic_case("c = 0.25 mm", 0.25, 0.0),
        synthetic_case("c = 0.50 mm", 0.5, 1.0),
    ];
    for kind in FigureKind::ALL {
        let fig = Figure {
            kind,
            title: "test figure",
            cases: &cases,
        };
        let [png_path, svg_path] = fig.write(&out, kind.stem()).unwrap();
        let bytes = std::fs::read(&png_path).unwrap();
        assert_eq!(png_size(&bytes), fig.size());
        // Decode it whole: the pixels must not all be the white background.
        let decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        let pixels = &buf[..info.buffer_size()];
        let dark = pixels
            .chunks(3)
            .filter(|p| p.iter().all(|&c| c < 100))
            .count();
        assert!(
            dark > 1000,
            "{kind:?}: only {dark} dark pixels (text and lines)"
        );
        let svg = std::fs::read_to_string(&svg_path).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("test figure"));
        let unit = match kind {
            FigureKind::Trajectory => "eccentricity u (mm)",
            _ => "time (s)",
        };
        assert!(svg.contains(unit), "{kind:?} lacks the axis label `{unit}`");
        assert!(svg.contains("c = 0.50 mm"), "{kind:?} lacks the legend");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// The paper's conclusion 2 on our model, at the study's settings (5 s, the default adaptive
/// steps): more impacts (contact onsets) and a higher peak force as the clearance grows (218, 249,
/// 281 onsets; 97.9, 137.5, 179.2 N). Over short runs the impact order is reversed (smaller clearances strike more often
/// at first; the report shows the counts per second), so this needs the whole 5 s.
#[test]
fn clearance_study_shows_more_impacts_and_higher_peaks_as_c_grows() {
    let root = scratch("clearance-study");
    let options = StudyOptions {
        exec: quiet(),
        extra_overrides: Vec::new(),
        no_figures: true,
    };
    let paper = Scene::solar_panel();
    let outcomes = run_studies(
        &select(&paper, "clearance").unwrap(),
        &paper,
        &root,
        &options,
    )
    .unwrap();
    let study = &outcomes[0];
    let h: Vec<_> = study
        .cases
        .iter()
        .map(|c| c.metrics.hinges["hinge"].clone())
        .collect();
    let cs: Vec<f64> = h.iter().map(|m| m.clearance_mm).collect();
    assert_eq!(cs, [0.1, 0.25, 0.5]);
    let impacts: Vec<u64> = h.iter().map(|m| m.onsets).collect();
    let peaks: Vec<f64> = h.iter().map(|m| m.peak_force_n).collect();
    assert!(
        impacts.windows(2).all(|w| w[1] > w[0]),
        "impacts {impacts:?}"
    );
    assert!(peaks.windows(2).all(|w| w[1] > w[0]), "peaks {peaks:?}");
    let report = std::fs::read_to_string(&study.report).unwrap();
    assert!(report.contains("Larger clearance: more impacts"));
    assert!(report.contains("**more impacts: yes.**"), "{report}");
    let c2 = study.conclusions.iter().find(|c| c.number == 2).unwrap();
    assert_ne!(c2.verdict, Verdict::NotTested);
    let table = MetricsTable::load(&root.join("clearance").join("metrics.json")).unwrap();
    assert_eq!(table.rows.len(), 3);
    let _ = std::fs::remove_dir_all(&root);
}

/// Issue 10 item 5: the paper's studies are declared in its scene file, exactly as they were
/// built into the app before (same paths, values as written, fixed settings in the same order,
/// labels), so their folders, tables and reports are unchanged.
#[test]
fn the_papers_presets_are_declared_in_its_scene() {
    let scene = Scene::solar_panel();
    let studies = clearance_joint_app::study::presets(&scene).unwrap();
    let common = [
        "run.step=Adaptive",
        "run.output_interval_s=1e-4",
        "run.end_s=5",
    ];
    // Name, swept path, values, labels, and the settings after the common ones.
    type Preset<'a> = (&'a str, &'a str, &'a [&'a str], &'a [&'a str], [&'a str; 2]);
    let expected: [Preset; 3] = [
        (
            "clearance",
            "hinge.clearance_mm",
            &["0.10", "0.25", "0.50"],
            &["c = 0.10 mm", "c = 0.25 mm", "c = 0.50 mm"],
            ["drive.torque_scale=1", "hinge.friction=Dry"],
        ),
        (
            "torque",
            "drive.torque_scale",
            &["1", "3", "5"],
            &["T", "3T", "5T"],
            ["hinge.clearance_mm=0.5", "hinge.friction=Dry"],
        ),
        (
            "friction",
            "hinge.friction",
            &["Dry", "Lubricated"],
            &["dry (no lubrication)", "lubricated"],
            ["hinge.clearance_mm=0.5", "drive.torque_scale=1"],
        ),
    ];
    assert_eq!(studies.len(), 3);
    for (s, (name, path, values, labels, fixed)) in studies.iter().zip(expected) {
        assert_eq!(s.name(), name);
        assert_eq!(s.axis(), Axis::new(path, values.iter().copied()));
        assert_eq!(s.labels(), labels);
        let set: Vec<&str> = common.iter().chain(&fixed).copied().collect();
        assert_eq!(s.spec.set, set, "{name}");
        assert_eq!(s.hinge, "hinge");
        assert!(s.paper && s.declared, "{name}");
    }
    // `study all` is every preset; a name the scene does not declare is refused, listing them.
    assert_eq!(select(&scene, "all").unwrap(), studies);
    let e = select(&scene, "stiffness").unwrap_err().to_string();
    assert!(
        e.contains("unknown study `stiffness`")
            && e.contains("`clearance`, `torque`, `friction`, or `all`"),
        "{e}"
    );
    // The paper's presets on a scene that is not the paper's (a heavier panel) judge nothing.
    let mut heavier = scene.clone();
    heavier.bodies[1].mass_kg *= 2.0;
    assert!(
        clearance_joint_app::study::presets(&heavier)
            .unwrap()
            .iter()
            .all(|s| s.spec.paper && !s.paper)
    );
}

/// A study of a scene that is not the paper's: the preset's cases run, the report says why it
/// judges none of the paper's conclusions, and nothing cites the paper's figures.
#[test]
fn a_paper_preset_off_the_paper_scene_gives_no_verdict() {
    let root = scratch("off-paper");
    let mut scene = Scene::solar_panel();
    scene.bodies[1].mass_kg *= 2.0;
    let options = StudyOptions {
        exec: quiet(),
        extra_overrides: vec!["run.end_s=0.01".into()],
        no_figures: true,
    };
    let outcomes = run_studies(
        &select(&scene, "friction").unwrap(),
        &scene,
        &root,
        &options,
    )
    .unwrap();
    assert_eq!(outcomes[0].cases.len(), 2);
    assert!(outcomes[0].conclusions.is_empty());
    let report = std::fs::read_to_string(&outcomes[0].report).unwrap();
    assert!(
        report.contains("is not the paper's scene") && !report.contains("paper section"),
        "{report}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// Issue 10 item 5: a preset declared in another scene's file runs from the command line by its
/// name (the slider-crank's clearance study of its rod-slider pin, cut to 2 ms), with figures of
/// that pin and a report that judges nothing of the paper; an undeclared name lists the presets.
#[test]
fn a_scene_declares_its_own_study() {
    let root = scratch("slider-study");
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/slider_crank.ron");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .args(["study", "pin_clearance", "--scene"])
        .arg(&scene)
        .args([
            "--set",
            "run.end_s=0.002",
            "--no-check",
            "--progress",
            "quiet",
            "--out",
        ])
        .arg(&root)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains("pin_clearance study ->"), "{stdout}");
    for label in ["c = 0.25 mm", "c = 0.5 mm", "c = 1.0 mm"] {
        assert!(stdout.contains(label), "{stdout}");
    }
    assert!(!stdout.contains("paper conclusion"), "{stdout}");
    let dir = root.join("pin_clearance");
    let table = MetricsTable::load(&dir.join("metrics.json")).unwrap();
    let cs: Vec<f64> = table
        .rows
        .iter()
        .map(|r| r.metrics.hinges["slider_pin"].clearance_mm)
        .collect();
    assert_eq!(cs, [0.25, 0.5, 1.0]);
    assert!(table.rows.iter().all(|r| r.metrics.end_s == 0.002));
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(
        report.contains(
            "# pin_clearance study: Influence of the clearance size (`slider_pin.clearance_mm`)"
        ) && report.contains("Not judged")
            && report.contains("![trajectory](trajectory.png)")
            && !report.contains("paper fig."),
        "{report}"
    );
    assert!(dir.join("joint_force.png").is_file());
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .args(["study", "clearance", "--scene"])
        .arg(&scene)
        .arg("--out")
        .arg(&root)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        e.contains("unknown study `clearance`: scene `slider_crank` declares `pin_clearance`"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// A general study: any field by its path (here the pendulum's arm mass, as numbers), the report
/// showing the scene's first clearance hinge; it judges none of the paper's conclusions.
#[test]
fn a_field_study_varies_any_path() {
    let text = include_str!("../../assets/pendulum.ron");
    let end = text.rfind(')').unwrap();
    let scene = Scene::from_ron(
        &format!(
            "{}    studies: [(name: \"mass\", kind: Field(path: \"arm.mass_kg\"), values: [1, 2.5], \
             set: [\"run.end_s=0.02\"])],\n{}",
            &text[..end],
            &text[end..]
        ),
        "pendulum with a study",
    )
    .unwrap();
    let root = scratch("field");
    let options = StudyOptions {
        exec: quiet(),
        extra_overrides: Vec::new(),
        no_figures: true,
    };
    let studies = select(&scene, "all").unwrap();
    assert_eq!(studies[0].hinge, "pivot");
    let outcomes = run_studies(&studies, &scene, &root, &options).unwrap();
    let o = &outcomes[0];
    let masses: Vec<f64> = o.cases.iter().map(|c| c.scene.bodies[1].mass_kg).collect();
    assert_eq!(masses, [1.0, 2.5]);
    assert_eq!(o.cases[1].label, "arm.mass_kg = 2.5");
    assert!(o.cases.iter().all(|c| c.metrics.end_s == 0.02));
    assert!(o.conclusions.is_empty());
    let report = std::fs::read_to_string(&o.report).unwrap();
    assert!(
        report.starts_with("# mass study: Influence of `arm.mass_kg`")
            && report.contains("| arm.mass_kg = 1 |")
            && report.contains("this preset is not one of them"),
        "{report}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// Issue 17, item 2: a grid too large for the memory budget is refused before any point is
/// built, with the numbers. Four axes of 100 values (1e8 points) would take GBs if the points
/// were built; under a 64 MB budget the refusal returns at once and nothing is written.
#[test]
fn a_huge_grid_is_refused_without_allocating() {
    let values: Vec<String> = (1..=100).map(|i| format!("{}", i as f64 * 1e-3)).collect();
    let axes = vec![
        Axis::new("hinge.clearance_mm", values.clone()),
        Axis::new("hinge.eta_s", values.clone()),
        Axis::new("drive.torque_scale", values.iter().map(|v| format!("1{v}"))),
        Axis::new("run.end_s", values.clone()),
    ];
    let sweep = Sweep::new(
        "huge",
        Scene::solar_panel(),
        vec![],
        Grid::new(axes).unwrap(),
    );
    assert_eq!(sweep.grid.len(), 100_000_000);
    let out = scratch("huge");
    let e = sweep
        .run(
            &out,
            Shard::ALL,
            ExecOptions {
                max_memory: Some(64 << 20),
                ..quiet()
            },
        )
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("sweep grid")
            && e.contains("100000000 points")
            && e.contains("--shard")
            && e.contains("budget"),
        "{e}"
    );
    assert!(!out.join("points").exists(), "nothing ran");
    // A value given twice (as the scene reads it) is refused.
    let e = Grid::new(vec![Axis::new(
        "hinge.clearance_mm",
        ["0.1", "0.25", "0.10"],
    )])
    .unwrap_err()
    .to_string();
    assert!(e.contains("`0.1` and `0.10`"), "{e}");
    let _ = std::fs::remove_dir_all(&out);
}

/// Issue 17, item 5: two axes naming one field by different paths are refused; paths resolve
/// to the field they name.
#[test]
fn two_paths_to_one_field_are_one_axis() {
    let scene = Scene::solar_panel();
    assert_eq!(
        scene.override_field("hinge.clearance_mm").unwrap(),
        scene
            .override_field("hinges[hinge].clearance.clearance_mm")
            .unwrap()
    );
    assert_eq!(
        scene.override_field("hinge.clearance_mm").unwrap(),
        "hinges[hinge].clearance.clearance_mm"
    );
    let sweep = Sweep::new(
        "twice",
        scene,
        vec![],
        Grid::new(vec![
            Axis::new("hinge.clearance_mm", ["0.1", "0.2"]),
            Axis::new("hinges[hinge].clearance.clearance_mm", ["0.3", "0.4"]),
        ])
        .unwrap(),
    );
    let e = sweep.check().unwrap_err().to_string();
    assert!(
        e.contains("hinges[hinge].clearance.clearance_mm") && e.contains("same field"),
        "{e}"
    );
}

/// Issue 17, item 3: a case read back in one pass keeps every extreme of every time series
/// (per bin), the first and last rows, and counts every contact onset of the full series.
#[test]
fn streamed_cases_keep_peaks_and_onsets() {
    use clearance_joint_app::figures::series::read_csv;
    let out = scratch("stream");
    let sweep = Sweep::new(
        "stream",
        Scene::solar_panel(),
        vec![
            "run.step=Fixed".into(),
            "run.dt_s=1e-5".into(),
            "run.output_interval_s=1e-5".into(),
            "run.end_s=0.3".into(),
        ],
        Grid::default(),
    );
    let done = sweep.run(&out, Shard::ALL, quiet()).unwrap();
    let dir = &done.points[0].dir;
    let scene = Scene::solar_panel()
        .with_overrides(&sweep.base_overrides)
        .unwrap();
    let full = CaseSeries::load_hinge("c", &scene, "hinge", dir).unwrap();
    let s = CaseSeries::stream("c", &scene, "hinge", dir).unwrap();
    let n = full.t_s.len();
    assert_eq!(s.rows, n);
    assert!(n > 20_000, "{n} rows");
    let kept = s.series.t_s.len();
    assert!(kept < n / 2, "kept {kept} of {n}");
    assert!(
        s.series.t_s.windows(2).all(|w| w[0] < w[1]),
        "rows in order"
    );
    assert_eq!(s.series.t_s.first(), full.t_s.first());
    assert_eq!(s.series.t_s.last(), full.t_s.last());
    let extremes = |v: &[f64]| {
        v.iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)))
    };
    assert_eq!(extremes(&s.series.force_n), extremes(&full.force_n));
    assert_eq!(
        extremes(&s.series.force_ideal_n),
        extremes(&full.force_ideal_n)
    );
    for (a, b) in s.series.bodies.iter().zip(&full.bodies) {
        assert_eq!(
            extremes(&a.rate_deg_s),
            extremes(&b.rate_deg_s),
            "{}",
            a.name
        );
        assert_eq!(extremes(&a.angle_deg), extremes(&b.angle_deg), "{}", a.name);
    }
    let onsets = onset_times(&full.t_s, &full.contact);
    assert!(!onsets.is_empty());
    assert_eq!(s.onsets_s, onsets);
    // The path: its ends kept, no point dropped farther than c / 800 from a kept one.
    assert_eq!(s.series.ecc_u_mm.first(), full.ecc_u_mm.first());
    assert_eq!(s.series.ecc_u_mm.last(), full.ecc_u_mm.last());
    assert!(s.series.ecc_u_mm.len() < n);
    // Unused here but the reader of the full tables still reads them whole.
    assert!(read_csv(&dir.join("ideal.csv")).is_ok());
    let _ = std::fs::remove_dir_all(&out);
}

/// Issue 17, items 8 and 9: labels with `|` or a line break do not break the report's
/// tables, and `--strict` fails a study whose case leaves the model's validity.
#[test]
fn report_labels_are_escaped() {
    let root = scratch("labels");
    let mut scene = Scene::solar_panel();
    let spec = scene
        .studies
        .iter_mut()
        .find(|s| s.name == "clearance")
        .unwrap();
    spec.labels = vec!["c | small".into(), "two\nlines".into(), "c = 0.5|".into()];
    let options = StudyOptions {
        exec: quiet(),
        extra_overrides: vec!["run.end_s=0.02".into()],
        no_figures: true,
    };
    let o = run_studies(
        &select(&scene, "clearance").unwrap(),
        &scene,
        &root,
        &options,
    )
    .unwrap();
    let report = std::fs::read_to_string(&o[0].report).unwrap();
    let cells = |line: &str| line.replace("\\|", "").matches('|').count();
    let mut tables = 0;
    let mut header = 0;
    for line in report.lines() {
        if !line.starts_with('|') {
            header = 0;
            continue;
        }
        if header == 0 {
            header = cells(line);
            tables += 1;
        }
        assert_eq!(cells(line), header, "{line}\n{report}");
    }
    assert!(tables >= 2, "{report}");
    assert!(
        report.contains("c \\| small") && report.contains("two lines"),
        "{report}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// A study checks each case's convergence by default: the console and the report say per case
/// which metrics converged and what the check cost, the table records the verdict (JSON) and
/// the count not converged (CSV). `--no-check` skips it and the report says so; a later run
/// with the check runs those cases again (they have no verdict), and the next reuses them.
#[test]
fn a_study_checks_each_case_and_reports_which_metrics_converged() {
    let study = |root: &PathBuf, extra: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
            .args(["study", "clearance", "--set", "run.end_s=0.1"])
            .args(["--no-figures", "--no-replay", "--progress", "quiet"])
            .args(extra)
            .arg("--out")
            .arg(root)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let dir = root.join("clearance");
        let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
        let table = MetricsTable::load(&dir.join("metrics.json")).unwrap();
        let csv = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
        (stdout, report, table, csv)
    };
    let labels = ["c = 0.10 mm", "c = 0.25 mm", "c = 0.50 mm"];
    let root = scratch("check");
    let (stdout, report, table, csv) = study(&root, &[]);
    assert_eq!(
        stdout
            .matches("convergence: converged: all 8 metrics within their bounds")
            .count(),
        3,
        "{stdout}"
    );
    assert!(report.contains("Convergence (each case against itself at half the tolerance"));
    for label in labels {
        let line = report
            .lines()
            .find(|l| l.starts_with(&format!("- {label}: ")))
            .unwrap_or_else(|| panic!("no convergence line for {label}: {report}"));
        assert!(
            line.contains("converged: all 8 metrics within their bounds")
                && line.contains("the check ")
                && line.contains("times the run's wall time"),
            "{line}"
        );
    }
    for row in &table.rows {
        let v = &row.metrics.convergence;
        assert!(v.is_checked() && v.not_converged().is_empty(), "{v:?}");
    }
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "not_converged").unwrap();
    assert!(lines.all(|l| l.split(',').nth(col) == Some("0")), "{csv}");
    let _ = std::fs::remove_dir_all(&root);

    let root = scratch("no-check");
    let (stdout, report, table, csv) = study(&root, &["--no-check"]);
    assert_eq!(
        stdout.matches("convergence: not checked").count(),
        3,
        "{stdout}"
    );
    assert!(
        report.contains("- c = 0.10 mm: not checked") && !report.contains("the check "),
        "{report}"
    );
    assert!(
        table
            .rows
            .iter()
            .all(|r| !r.metrics.convergence.is_checked())
    );
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "not_converged").unwrap();
    assert!(lines.all(|l| l.split(',').nth(col) == Some("")), "{csv}");
    // Checked now: the unchecked cases run again; then they are reused with their verdicts.
    let (stdout, report, _, _) = study(&root, &[]);
    assert!(!stdout.contains("[reused]"), "{stdout}");
    assert!(!report.contains("not checked"), "{report}");
    let (stdout, _, table, _) = study(&root, &[]);
    assert_eq!(stdout.matches("[reused]").count(), 3, "{stdout}");
    assert!(
        table
            .rows
            .iter()
            .all(|r| r.metrics.convergence.is_checked())
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// A study's force figure shows each case's peak from every step of its run (the contact
/// list's `peak_t_s`, read back from the point), not the rows' lower maximum: each case's
/// legend reads its metrics' `peak_force_n`.
#[test]
fn study_force_figures_show_each_case_peak() {
    let out = scratch("study-peaks");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_clearance_joint"))
        .args([
            "study",
            "friction",
            "--set",
            "run.end_s=0.12",
            "--progress",
            "quiet",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let dir = out.join("friction");
    let table: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    let svg = std::fs::read_to_string(dir.join("joint_force.svg")).unwrap();
    let rows = table["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for row in rows {
        let peak = row["metrics"]["hinges"]["hinge"]["peak_force_n"]
            .as_f64()
            .unwrap();
        let legend = format!("clearance joint, peak {peak:.4} N");
        assert!(
            svg.contains(&legend),
            "no `{legend}` in the study's joint_force.svg"
        );
        let point = out.join("friction").join(row["dir"].as_str().unwrap());
        let rows = clearance_joint_app::figures::series::read_csv(&point.join("clearance.csv"))
            .unwrap()
            .column("hinge_force_n")
            .unwrap()
            .into_iter()
            .fold(0.0, f64::max);
        assert!(rows < peak * (1.0 - 1e-3), "rows {rows} vs {peak}");
    }
    let _ = std::fs::remove_dir_all(&out);
}
