//! Bad scene files and command lines as a careless user or script makes them, one test per
//! class: each is refused with one line on stderr starting `error:` that names the file (and
//! line, key or flag), the value and what is admissible; the exit code says usage (2) or input
//! (1); nothing is left behind. Limits that guard against hangs are checked under a watchdog.

mod common;

use common::refusal::{RENDER, listing, refused, render_refused, run_in, scratch};

#[test]
fn scenes_past_the_object_limit_are_refused_quickly() {
    // 200 000 objects: twice the limit. Finding the line of a key was quadratic (40 000
    // objects took 29 s); the watchdog allows a minute, the parse takes well under one.
    let mut text = common::MINIMAL.to_string();
    for i in 0..200_000 {
        text.push_str(&format!(
            "\n[[object]]\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.1\ntranslate = [{}.0, 0.1, -20.0]\n",
            i % 1000
        ));
    }
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(common::parse(&text).map(|s| s.objects.len()));
    });
    let result = receive
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("parsing 200 000 objects must not hang");
    let err = result.expect_err("past the object limit");
    let shown = err.to_string();
    assert!(
        shown.contains("100000") && shown.contains("object"),
        "{shown}"
    );
    assert!(!shown.contains('\n'));
}

#[test]
fn usage_and_toml_syntax_errors_are_one_line() {
    let dir = scratch("", &[]);
    for (args, words) in [
        (
            &["render"][..],
            &["required arguments", "--out", "<SCENE>"][..],
        ),
        (&["render", "scene.toml", "--bogus", "1"], &["'--bogus'"]),
        (
            &["render", "scene.toml", "--out", "o", "--view", "rear"],
            &["'rear'", "possible values"],
        ),
        (
            &["render", "scene.toml", "--out", "o", "--width"],
            &["--width", "none was supplied"],
        ),
        (
            &["measure", "o", "--band", "4000000000"],
            &["--band", "[1, 1000]"],
        ),
        (&["frobnicate"], &["'frobnicate'"]),
    ] {
        refused(dir.path(), args, 2, words);
    }
    assert_eq!(listing(dir.path()), ["scene.toml"]);
    for (toml, words) in [
        ("\n[obstacle\n", &["scene.toml:", "invalid TOML"][..]),
        ("\nx = \"never closed\n", &["scene.toml:", "invalid TOML"]),
        (
            "\n[[object]]\nkind = = 1\n",
            &["scene.toml:", "invalid TOML"],
        ),
    ] {
        let dir = scratch(toml, &[]);
        let text = std::fs::read_to_string(dir.path().join("scene.toml")).unwrap();
        let last = toml.trim_end().lines().last().unwrap();
        let line = text
            .lines()
            .collect::<Vec<_>>()
            .iter()
            .rposition(|l| *l == last)
            .unwrap()
            + 1;
        let err = render_refused(dir.path(), words);
        assert!(
            err.contains(&format!("scene.toml:{line}:")),
            "{err} (line {line})"
        );
    }
}

#[test]
fn names_given_twice_say_which() {
    let dir = scratch(
        "\n[[material]]\nname = \"grey\"\ncolor = [0.1, 0.1, 0.1]\n",
        &[],
    );
    render_refused(
        dir.path(),
        &[
            "material[1].name",
            "material `grey` is defined twice",
            "line",
        ],
    );
    let dir = scratch(
        "\n[[object]]\nname = \"ball\"\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.5\n",
        &[],
    );
    render_refused(
        dir.path(),
        &[
            "object[2].name",
            "object `ball` is named twice",
            "object[2]",
            "line",
        ],
    );
    // Default names (the kind) may repeat.
    let dir = scratch(
        "\n[[object]]\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.5\n\n[[object]]\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.5\ntranslate = [2.0, 0.0, -10.0]\n",
        &[],
    );
    assert_eq!(run_in(dir.path(), RENDER).0, 0);
}

#[test]
fn numbers_in_messages_are_short_and_ranges_run_low_to_high() {
    for (from, to) in [
        ("width = 0.3", "width = 123456789012345678901234567890.5"),
        (
            "width = 0.3",
            "width = 0.30000000000000004440892098500626161694526672363281250000000001",
        ),
        ("radius = 1.0", "radius = -1e300"),
        ("size = [100.0, 100.0]", "size = [100.0, 1e-300]"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("scene.toml"),
            common::MINIMAL
                .replacen(from, to, 1)
                .replace("width = 0.3", "width = 200.0"),
        )
        .unwrap();
        let err = render_refused(dir.path(), &["scene.toml:"]);
        let longest_number = err
            .split(|c: char| !(c.is_ascii_digit() || c == '.'))
            .map(str::len)
            .max()
            .unwrap_or(0);
        assert!(longest_number <= 12, "a long number in `{err}`");
        // Every `[lo, hi]` in the message has lo ≤ hi.
        for range in err.split('[').skip(1) {
            let Some((inside, _)) = range.split_once(']') else {
                continue;
            };
            let bounds: Vec<f64> = inside
                .split(',')
                .filter_map(|b| b.trim().parse().ok())
                .collect();
            if let [lo, hi] = bounds[..] {
                assert!(lo <= hi, "range [{inside}] runs high to low in `{err}`");
            }
        }
    }
}

#[test]
fn every_sweep_parameter_refuses_values_outside_its_documented_range() {
    use seethru::measure::sweep_grid::{PARAMETERS, parse_param};
    // (name, low, high, unit): the ranges of the scene keys and options each parameter sets
    // (camera.frontal.half_angle_deg, obstacle.width, lengths of the scene, the world,
    // --head-bias-cm, image sides), both ends included. Tiny positive values (1e-300, 5e-324)
    // wrote rows of NaN for θ_F and the display width.
    let documented = |name: &str| match name {
        "theta_f" => (0.01, 89.0, "degrees", "[0.01, 89]"),
        "d2" => (1e-6, 1e6, "m", "[1e-6, 1e6]"),
        "display_width" => (1e-6, 100.0, "m", "[1e-6, 100]"),
        "eye_x" | "eye_z" => (-1e6, 1e6, "m", "[-1e6, 1e6]"),
        "head_bias_x_cm" => (-500.0, 500.0, "cm", "[-500, 500]"),
        "frontal_width" => (1.0, 16384.0, "pixels", "[1, 16384]"),
        other => panic!("`{other}` is not in this test"),
    };
    for (name, description) in PARAMETERS {
        if name == "eye" {
            // Not a number: the one value names the scene's eyellipse sampler.
            assert!(description.starts_with("eyellipse:"), "{description}");
            for written in ["eyellipse", " eyellipse "] {
                assert!(parse_param(&format!("eye={written}")).is_ok(), "{written}");
            }
            for written in ["1.2", "nan", "", "eyellipse,eyellipse", "ellipse"] {
                let e = parse_param(&format!("eye={written}")).unwrap_err();
                assert!(
                    format!("{e:#}").contains("the only value is eyellipse"),
                    "{e:#}"
                );
            }
            continue;
        }
        let (lo, hi, unit, range) = documented(name);
        assert!(
            description.contains(range),
            "{name}: {description} vs {range}"
        );
        // One past each end: the next integer, or 0.1 % beyond.
        let past = |x: f64, towards: f64| {
            if name == "frontal_width" {
                x + towards
            } else {
                x + towards * x.abs() * 1e-3
            }
        };
        let cases = [
            (format!("{lo}"), lo),
            (format!("{hi}"), hi),
            (format!("{}", past(lo, -1.0)), past(lo, -1.0)),
            (format!("{}", past(hi, 1.0)), past(hi, 1.0)),
            ("0".into(), 0.0),
            ("-1".into(), -1.0),
            ("1e-300".into(), 1e-300),
            ("5e-324".into(), 5e-324),
            ("nan".into(), f64::NAN),
            ("-inf".into(), f64::NEG_INFINITY),
            ("1e300".into(), 1e300),
        ];
        for (written, x) in cases {
            let admissible = x >= lo && x <= hi && (name != "frontal_width" || x.fract() == 0.0);
            match parse_param(&format!("{name}={written}")) {
                Ok(_) => assert!(admissible, "{name}={written} accepted ({description})"),
                Err(e) => {
                    let shown = format!("{e:#}");
                    assert!(!admissible, "{name}={written} refused: {shown}");
                    let shown_range = format!(
                        "[{}, {}] {unit}",
                        seethru::util::number::short(lo),
                        seethru::util::number::short(hi)
                    );
                    assert!(
                        !shown.contains('\n')
                            && shown.starts_with(&format!("{name} = "))
                            && shown.contains(&shown_range),
                        "{shown}"
                    );
                }
            }
        }
        // `inf` is d2's name for no planar correction; for every other parameter it is refused.
        assert_eq!(parse_param(&format!("{name}=inf")).is_ok(), name == "d2");
    }
    // The value that panicked in the BVH build (a 1e300 m display), through the command.
    let dir = scratch("", &[]);
    refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--param",
            "display_width=1e300",
            "--out",
            "s.csv",
        ],
        1,
        &["display_width = 1e300", "[1e-6, 100] m"],
    );
    refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--param",
            "eye_x=1,2,,3",
            "--out",
            "s.csv",
        ],
        1,
        &["empty value"],
    );
    refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--param",
            "eye_x=1",
            "--param",
            "eye_x=2",
            "--out",
            "s.csv",
        ],
        1,
        &["`eye_x` is given twice"],
    );
    assert_eq!(listing(dir.path()), ["scene.toml"]);
}

/// Runs seethru in `dir` under a watchdog of 60 s (killed past it); (exit code, stderr).
fn run_with_watchdog(dir: &std::path::Path, args: &[&str]) -> (i32, String) {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_seethru"))
        .arg("--quiet")
        .args(args)
        .current_dir(dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(60) {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("{args:?} still running after 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn sweep_grids_past_the_limit_and_repeated_values_are_refused_before_any_work() {
    let dir = scratch("", &[]);
    // 401 × 401 = 160 801 configurations, past the limit of 100 000 (the audit's 6·10⁹ ran out
    // of memory): refused at once, naming each count and the product.
    let (code, err) = run_with_watchdog(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--width",
            "8",
            "--param",
            "theta_f=40:80:0.1",
            "--param",
            "eye_x=0:0.4:0.001",
            "--out",
            "s.csv",
        ],
    );
    assert_eq!(code, 1, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains(
            "theta_f 401 × eye_x 401 = 160801 configurations, more than the limit of 100000"
        ),
        "{err}"
    );
    // The same value twice computed the same configuration twice.
    for (spec, words) in [
        ("d2=1,1", "d2: the value 1 is given twice"),
        ("d2=5,5,5", "d2: the value 5 is given twice"),
        ("d2=inf,infinity", "d2: infinity is the value inf again"),
        ("theta_f=30,30.0", "theta_f: 30.0 is the value 30 again"),
    ] {
        refused(
            dir.path(),
            &["sweep", "scene.toml", "--param", spec, "--out", "s.csv"],
            1,
            &[words],
        );
    }
    assert_eq!(listing(dir.path()), ["scene.toml"]);
    // Spaces around values are ignored, as around every number of the command line
    // (`--width ' 5'`): `d2= 5` is `d2=5`, and resumes its CSV.
    let mut first: Option<String> = None;
    for spec in ["d2=5", "d2= 5", "d2=5 ", " d2 = 5.0"] {
        let (code, err) = run_in(
            dir.path(),
            &[
                "sweep",
                "scene.toml",
                "--width",
                "8",
                "--param",
                spec,
                "--out",
                "s.csv",
            ],
        );
        assert_eq!(code, 0, "{spec}: {err}");
        let csv = std::fs::read_to_string(dir.path().join("s.csv")).unwrap();
        assert_eq!(&csv, first.get_or_insert_with(|| csv.clone()), "{spec}");
    }
    let (code, err) = run_in(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--width",
            "8",
            "--param",
            "theta_f= 40 : 60 : 20",
            "--out",
            "t.csv",
        ],
    );
    assert_eq!(code, 0, "{err}");
}

#[test]
fn sweep_outputs_that_are_no_file_and_csvs_of_other_sweeps_are_named() {
    let dir = scratch("", &[]);
    std::fs::create_dir(dir.path().join("folder")).unwrap();
    for (out, words) in [
        ("folder", vec!["--out folder: it is a folder, not a file"]),
        (
            "new/",
            vec!["--out new/: names a folder, not a file", "new/sweep.csv"],
        ),
        (
            "/dev/null",
            vec!["--out /dev/null: it is not a regular file"],
        ),
    ] {
        refused(
            dir.path(),
            &["sweep", "scene.toml", "--param", "d2=5", "--out", out],
            1,
            &words,
        );
        refused(
            dir.path(),
            &["sweep-merge", "scene.toml", "--out", out],
            1,
            &words,
        );
    }
    // clap refuses an empty --out (the library refuses it too: `--out is empty`).
    refused(
        dir.path(),
        &["sweep", "scene.toml", "--param", "d2=5", "--out", ""],
        2,
        &["'--out <OUT>'"],
    );
    assert_eq!(listing(dir.path()), ["folder", "scene.toml"]);
    // A CSV of another sweep, or an empty one: both headers are named, up to where they
    // differ.
    std::fs::write(
        dir.path().join("other.csv"),
        "index,theta_f,misregistration_mean_arcmin\n",
    )
    .unwrap();
    refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--param",
            "d2=5",
            "--out",
            "other.csv",
        ],
        1,
        &[
            "other.csv exists with other columns: it has the columns `index,theta_f,…` (3), expected `index,d2,…` (21): column 2 is `theta_f` where `d2` belongs",
        ],
    );
    std::fs::write(dir.path().join("empty.csv"), "").unwrap();
    refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--param",
            "d2=5",
            "--out",
            "empty.csv",
        ],
        1,
        &["empty.csv exists but is empty (no header; expected `index,d2,…` (21))"],
    );
}

#[test]
fn scenes_past_the_triangle_limit_are_refused_before_building() {
    // 1 300 cylinders of 4 096 segments are about 21 million triangles: past the limit of
    // 20 million, refused while parsing (no mesh, no BVH built).
    let mut text = common::MINIMAL.to_string();
    for i in 0..1300 {
        text.push_str(&format!(
            "\n[[object]]\nkind = \"cylinder\"\nmaterial = \"grey\"\nsegments = 4096\ntranslate = [{i}.0, 0.0, -30.0]\n"
        ));
    }
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(common::parse(&text).map(|s| s.objects.len()));
    });
    let err = receive
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("must not hang")
        .expect_err("past the triangle limit");
    let shown = err.to_string();
    assert!(
        shown.contains("20000000") && shown.contains("triangles"),
        "{shown}"
    );
    assert!(
        shown.starts_with("test-scenes/scene.toml:") && !shown.contains('\n'),
        "{shown}"
    );
}

#[test]
fn numbers_pasted_with_hundreds_of_digits_are_not_repeated_in_full() {
    let long = format!("1{}.5", "0".repeat(800));
    let dir = scratch("", &[]);
    for (args, code) in [
        (vec!["measure", "run", "--band", long.as_str()], 2),
        (
            vec![
                "render",
                "scene.toml",
                "--out",
                "o",
                "--width",
                long.as_str(),
            ],
            2,
        ),
        (
            vec!["run", "scene.toml", "--out", "o", "--d2", long.as_str()],
            2,
        ),
    ] {
        let err = refused(dir.path(), &args, code, &["100000000000…(803 characters)"]);
        assert!(err.len() < 300, "{err}");
    }
    let param = format!("theta_f={long}");
    let err = refused(
        dir.path(),
        &["sweep", "scene.toml", "--param", &param, "--out", "s.csv"],
        1,
        &["theta_f", "(803 characters)"],
    );
    assert!(err.len() < 300, "{err}");
    assert_eq!(listing(dir.path()), ["scene.toml"]);
}

#[test]
#[cfg(unix)]
fn inputs_that_are_devices_or_folders_are_refused_without_being_read() {
    // /dev/zero reports a size of 0 and never ends: read whole, it took all the memory (a
    // scene, an `mtllib`, a sweep CSV to resume, a head path). Each input is refused before a
    // byte is read, under a watchdog, naming the file as written.
    let obj = "mtllib zero.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let mesh = "\n[[object]]\nkind = \"mesh\"\npath = \"m.obj\"\n";
    let dir = scratch(mesh, &[("m.obj", obj.as_bytes())]);
    let zero = std::path::Path::new("/dev/zero");
    for link in ["zero.toml", "zero.mtl", "zero.csv", "zero_path.csv"] {
        std::os::unix::fs::symlink(zero, dir.path().join(link)).unwrap();
    }
    std::fs::create_dir(dir.path().join("folder.toml")).unwrap();
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["render", "zero.toml", "--out", "out"],
            vec!["zero.toml", "not a regular file"],
        ),
        (
            vec!["render", "folder.toml", "--out", "out"],
            vec!["folder.toml", "a folder, not a file"],
        ),
        (RENDER.to_vec(), vec!["zero.mtl", "not a regular file"]),
        (
            vec![
                "sweep",
                "scene.toml",
                "--param",
                "d2=5",
                "--out",
                "zero.csv",
            ],
            vec!["zero.csv", "not a regular file"],
        ),
        (
            vec![
                "sequence",
                "scene.toml",
                "--head-path",
                "zero_path.csv",
                "--out",
                "out",
            ],
            vec!["zero_path.csv", "not a regular file"],
        ),
        (
            vec!["sweep-merge", "zero.csv", "--out", "merged.csv"],
            vec!["zero.csv", "not a regular file"],
        ),
    ];
    for (args, words) in cases {
        let before = listing(dir.path());
        let (send, receive) = std::sync::mpsc::channel();
        let (path, owned): (std::path::PathBuf, Vec<String>) = (
            dir.path().to_path_buf(),
            args.iter().map(|a| a.to_string()).collect(),
        );
        let words: Vec<String> = words.iter().map(|w| w.to_string()).collect();
        std::thread::spawn(move || {
            let args: Vec<&str> = owned.iter().map(String::as_str).collect();
            let words: Vec<&str> = words.iter().map(String::as_str).collect();
            let _ = send.send(refused(&path, &args, 1, &words));
        });
        receive
            .recv_timeout(std::time::Duration::from_secs(60))
            .unwrap_or_else(|_| panic!("{args:?} did not end within a minute"));
        assert_eq!(listing(dir.path()), before, "{args:?} left files behind");
    }
}

#[test]
fn names_with_line_breaks_or_terminal_escapes_are_shown_inert() {
    // A name is echoed in the error: its line break must not split the message, its escape
    // sequence must not reach the terminal.
    let object =
        "\n[[object]]\nkind = \"sphere\"\nmaterial = \"no\\nsuch\\u001b[31m\"\nradius = 1.0\n";
    let dir = scratch(object, &[]);
    let err = render_refused(dir.path(), &["scene.toml", "no\\nsuch\\u{1b}[31m"]);
    assert!(!err.chars().any(char::is_control), "{err:?}");
}

#[test]
fn a_display_that_covers_no_pixel_is_refused_not_measured_as_empty() {
    // The driver looks away from the display, or it is too small to cover a pixel: every
    // metric would be undefined; `run` says why instead of writing a run of empty metrics.
    for (from, to) in [
        ("look_at = [0.0, 1.2, -10.0]", "look_at = [0.0, 1.2, 10.0]"),
        ("width = 0.3\nheight = 0.4", "width = 1e-5\nheight = 1e-5"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let scene = common::MINIMAL.replace(from, to);
        assert_ne!(scene, common::MINIMAL);
        std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
        refused(
            dir.path(),
            &["run", "scene.toml", "--out", "out", "--spp", "1"],
            1,
            &["the display covers no pixel of the driver's 64×36 view"],
        );
        assert!(!dir.path().join("out").exists());
    }
}

#[test]
fn flags_the_command_would_ignore_are_refused() {
    // Each was accepted and then ignored without a word: a sensor's settings for the ideal
    // sensor, a sensor or a fill for a method that reads none, a head path beside a head
    // preset, one latency twice (one folder each).
    let dir = scratch("", &[]);
    let run = ["run", "scene.toml", "--out", "out", "--spp", "1"];
    for (extra, words) in [
        (
            &["--depth-noise", "0.1"][..],
            &["--depth-noise is read only by --method plane-fit and depth"][..],
        ),
        (
            &["--method", "depth", "--depth-range", "5"],
            &[
                "--depth-range does not apply to --depth-sensor ideal",
                "--depth-sensor tof",
            ],
        ),
        (
            &["--method", "plane-fit", "--fill", "inpaint"],
            &["--fill is read only by --method depth"],
        ),
        (
            &["--depth-sensor", "stereo"],
            &["--depth-sensor is read only by --method plane-fit and depth"],
        ),
    ] {
        let args: Vec<&str> = run.iter().chain(extra).copied().collect();
        refused(dir.path(), &args, 1, words);
    }
    let sequence = ["sequence", "scene.toml", "--out", "out"];
    for (extra, words) in [
        (
            &["--head", "sway", "--head-path", "p.csv"][..],
            &["'--head <HEAD>' cannot be used with '--head-path <CSV>'"][..],
        ),
        (
            &["--latency-camera", "16,33,16.0000001"],
            &["latencies 16 and 16.0000001 ms", "give each once"],
        ),
    ] {
        let args: Vec<&str> = sequence.iter().chain(extra).copied().collect();
        refused(dir.path(), &args, 2, words);
    }
    assert_eq!(listing(dir.path()), vec!["scene.toml".to_string()]);
}

#[test]
fn a_size_flag_whose_aspect_breaks_the_pixel_limit_is_named() {
    // Each side is admissible, the image is not: the message names the flag, the size the
    // camera's aspect gives and the limit in pixels, not a 9-digit count.
    let dir = scratch("", &[]);
    let err = refused(
        dir.path(),
        &[
            "run",
            "scene.toml",
            "--out",
            "out",
            "--frontal-width",
            "16384",
        ],
        1,
        &[
            "--frontal-width gives 16384×9216",
            "at most 16384×8192 in all",
        ],
    );
    assert!(!err.contains("134217728"), "{err}");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn flags_that_diff_and_sweep_merge_would_ignore_are_refused_and_nothing_is_written() {
    let dir = scratch("", &[]);
    for k in ["0", "1"] {
        let (code, err) = run_in(
            dir.path(),
            &[
                "sweep",
                "scene.toml",
                "--param",
                "d2=2,5",
                "--width",
                "16",
                "--shard",
                &format!("{k}/2"),
                "--out",
                &format!("p{k}.csv"),
            ],
        );
        assert_eq!(code, 0, "{err}");
    }
    let (code, err) = run_in(
        dir.path(),
        &[
            "render",
            "scene.toml",
            "--view",
            "truth",
            "--width",
            "16",
            "--out",
            "r",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let before = listing(dir.path());
    // --bound-arcmin is read only for parts of an eye=eyellipse sweep (it was accepted and
    // dropped); the merge writes nothing when refused.
    refused(
        dir.path(),
        &[
            "sweep-merge",
            "p0.csv",
            "p1.csv",
            "--out",
            "m.csv",
            "--bound-arcmin",
            "3",
        ],
        1,
        &["--bound-arcmin", "eye=eyellipse", "(d2)"],
    );
    // --tolerance moves metrics.json's values: read only for two run folders.
    refused(
        dir.path(),
        &[
            "diff",
            "r/truth.png",
            "r/truth.png",
            "--tolerance",
            "misregistration.mean=1",
        ],
        2,
        &["--tolerance", "two run folders"],
    );
    assert_eq!(listing(dir.path()), before);
    // Without them, both run.
    let (code, err) = run_in(
        dir.path(),
        &["sweep-merge", "p0.csv", "p1.csv", "--out", "m.csv"],
    );
    assert_eq!(code, 0, "{err}");
    let (code, err) = run_in(dir.path(), &["diff", "r/truth.png", "r/truth.png"]);
    assert_eq!(code, 0, "{err}");
}
