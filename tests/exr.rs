//! The EXRs seethru writes: compressed losslessly (every bit of every sample read back), and
//! `--exr none|colour|all` writing what it says.

mod common;

use exr::prelude::*;
use seethru::io::frame_files::{
    EXR_COMPRESSION, ExrContent, channel, read_exr, write_exr_channels, write_frame,
};
use seethru::io::run_dir::read_measured_frames;
use seethru::render::frame::Frame;
use seethru::render::{integrator::RenderContext, render_job::RenderJob, settings::RenderSettings};
use seethru::scene::world::view_bit;
use seethru::util::sampling::hash_u32;

fn rendered() -> Frame {
    let ctx = RenderContext::new(common::parse(common::MINIMAL).unwrap()).unwrap();
    let camera = ctx.scene.driver.with_resolution(97, 61);
    let settings = RenderSettings {
        spp: 2,
        progress: false,
    };
    ctx.render(
        RenderJob::new(&camera, view_bit::TRUTH)
            .settings(settings)
            .label("test"),
    )
    .0
}

/// Every channel of the first layer of `path`, by name, as the exr crate reads it.
fn channels(path: &std::path::Path) -> Vec<(String, FlatSamples)> {
    let image = read_all_flat_layers_from_file(path).unwrap();
    let layer = &image.layer_data[0];
    layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.clone()))
        .collect()
}

fn bits(samples: &FlatSamples) -> Vec<u32> {
    match samples {
        FlatSamples::F32(v) => v.iter().map(|x| x.to_bits()).collect(),
        FlatSamples::U32(v) => v.clone(),
        FlatSamples::F16(v) => v.iter().map(|x| x.to_bits() as u32).collect(),
    }
}

#[test]
fn compressed_exrs_keep_every_bit_of_awkward_samples() {
    // Noise (the worst case of a wavelet coder), NaN payloads, both zeros, infinities,
    // subnormals and the largest values, as f32 and u32, at an odd size (partial blocks).
    let (width, height) = (131, 37);
    let n = width * height;
    let special = [
        f32::NAN.to_bits(),
        0x7fc0_1234,
        0xffff_ffff,
        0x8000_0000,
        0,
        f32::INFINITY.to_bits(),
        f32::NEG_INFINITY.to_bits(),
        1,
        0x807f_ffff,
        f32::MAX.to_bits(),
    ];
    let word = |i: usize, salt: u32| match i % 7 {
        0 => special[(i / 7) % special.len()],
        _ => hash_u32(i as u32 ^ salt.wrapping_mul(0x9e37_79b9)),
    };
    let f32s: Vec<f32> = (0..n).map(|i| f32::from_bits(word(i, 1))).collect();
    let smooth: Vec<f32> = (0..n).map(|i| (i as f32 * 0.01).sin() * 40.0).collect();
    let u32s: Vec<u32> = (0..n).map(|i| word(i, 2)).collect();
    let written = vec![
        ("noise", FlatSamples::F32(f32s)),
        ("smooth", FlatSamples::F32(smooth)),
        ("ids", FlatSamples::U32(u32s)),
    ];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("awkward.exr");
    let list = written
        .iter()
        .map(|(name, s)| AnyChannel::new(*name, s.clone()))
        .collect();
    write_exr_channels(&path, width as u32, height as u32, list).unwrap();
    let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
    assert_eq!(meta.headers[0].compression, EXR_COMPRESSION);
    assert_ne!(EXR_COMPRESSION, Compression::Uncompressed);
    let read = channels(&path);
    assert_eq!(read.len(), written.len());
    for (name, samples) in &written {
        let (_, back) = read.iter().find(|(n, _)| n == name).unwrap();
        assert_eq!(bits(back), bits(samples), "channel {name}");
    }
}

#[test]
fn a_rendered_frame_compresses_and_reads_back_bit_identical() {
    let frame = rendered();
    let dir = tempfile::tempdir().unwrap();
    write_frame(&frame, dir.path(), "truth", ExrContent::All).unwrap();
    let path = dir.path().join("truth.exr");
    assert!(frame.bit_identical(&read_exr(&path).unwrap()));
    // 17 channels of 4 bytes per pixel uncompressed; the sky and the flat ground compress.
    let raw = 17 * 4 * frame.color.len() as u64;
    let size = std::fs::metadata(&path).unwrap().len();
    assert!(
        size < raw * 3 / 4,
        "{size} bytes against {raw} uncompressed"
    );
}

#[test]
fn exr_content_writes_what_it_names() {
    let frame = rendered();
    let dir = tempfile::tempdir().unwrap();
    let names = |content: ExrContent| {
        let out = dir.path().join(format!("{content:?}"));
        write_frame(&frame, &out, "truth", content).unwrap();
        let mut files: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into())
            .collect();
        files.sort();
        (out, files)
    };
    let (_, none) = names(ExrContent::None);
    assert_eq!(none, ["truth.png", "truth_ids.png"]);
    let (out, colour) = names(ExrContent::Colour);
    assert_eq!(colour, ["truth.exr", "truth.png", "truth_ids.png"]);
    let read = channels(&out.join("truth.exr"));
    let mut read_names: Vec<&str> = read.iter().map(|(n, _)| n.as_str()).collect();
    read_names.sort();
    assert_eq!(read_names, ["A", "B", "G", "R"]);
    let [r, g, b, a] = channel::RGBA;
    for (i, name) in [r, g, b].into_iter().enumerate() {
        let (_, samples) = read.iter().find(|(n, _)| n == name).unwrap();
        let expected: Vec<u32> = frame.color.iter().map(|c| c[i].to_bits()).collect();
        assert_eq!(bits(samples), expected, "channel {name}");
    }
    let (_, alpha) = read.iter().find(|(n, _)| n == a).unwrap();
    assert!(bits(alpha).iter().all(|&x| x == 1f32.to_bits()));
    // A colour-only EXR is not a frame: reading it as one names the missing AOV.
    let err = read_exr(&out.join("truth.exr")).unwrap_err();
    assert!(format!("{err:#}").contains("no channel `Z`"), "{err:#}");
    let (out, all) = names(ExrContent::All);
    assert_eq!(all, colour);
    assert!(frame.bit_identical(&read_exr(&out.join("truth.exr")).unwrap()));
    let all_channels = channels(&out.join("truth.exr"));
    // Lean: the channels of `all` less A, P and camera_z.Z, every bit of them.
    let (out, lean) = names(ExrContent::Lean);
    assert_eq!(lean, colour);
    let read = channels(&out.join("truth.exr"));
    let mut read_names: Vec<&str> = read.iter().map(|(n, _)| n.as_str()).collect();
    read_names.sort();
    assert_eq!(
        read_names,
        [
            "B",
            "G",
            "N.X",
            "N.Y",
            "N.Z",
            "R",
            "Z",
            "id.object",
            "id.part"
        ]
    );
    for (name, samples) in &read {
        let (_, full) = all_channels.iter().find(|(n, _)| n == name).unwrap();
        assert_eq!(bits(samples), bits(full), "channel {name}");
    }
    let (_, z) = read.iter().find(|(n, _)| n == "Z").unwrap();
    let depth: Vec<u32> = frame.depth.iter().map(|d| d.to_bits()).collect();
    assert_eq!(bits(z), depth);
}

#[test]
fn measuring_a_run_without_aovs_names_the_flag() {
    let frame = rendered();
    let dir = tempfile::tempdir().unwrap();
    for content in [ExrContent::Lean, ExrContent::Colour, ExrContent::None] {
        let out = dir.path().join(format!("{content:?}"));
        for view in ["truth", "seethru", "occluded"] {
            write_frame(&frame, &out, view, content).unwrap();
        }
        let err = read_measured_frames(&out).unwrap_err().to_string();
        assert!(
            err.contains("truth.exr") && err.contains("option `exr` all"),
            "{err}"
        );
    }
    // Every AOV there: it reads.
    let out = dir.path().join("all");
    for view in ["truth", "seethru", "occluded"] {
        write_frame(&frame, &out, view, ExrContent::All).unwrap();
    }
    assert!(read_measured_frames(&out).unwrap()[0].bit_identical(&frame));
}

#[test]
fn seethru_zip_matches_the_exr_crates_zip_and_ignores_the_thread_count() {
    use seethru::io::exr_zip;
    // A rendered frame's every AOV, at a size that leaves partial tiles across and down.
    let frame = rendered();
    assert!(
        !frame.width.is_multiple_of(64) && !frame.height.is_multiple_of(64) && frame.width > 64
    );
    let dir = tempfile::tempdir().unwrap();
    let ours = dir.path().join("ours.exr");
    write_frame(&frame, dir.path(), "ours", ExrContent::All).unwrap();
    let meta = exr::meta::MetaData::read_from_file(&ours, false).unwrap();
    assert_eq!(meta.headers[0].compression, Compression::ZIP16);
    assert_eq!(exr_zip::COMPRESSION, Compression::ZIP16);
    assert!(
        matches!(meta.headers[0].blocks, exr::meta::BlockDescription::Tiles(t)
            if t.tile_size == Vec2(64, 64) && t.level_mode == exr::meta::attribute::LevelMode::Singular),
        "{:?}",
        meta.headers[0].blocks
    );
    assert!(frame.bit_identical(&read_exr(&ours).unwrap()));
    // The twin: the frame's channels through the exr crate's own writer of ZIP tiles.
    let theirs = dir.path().join("theirs.exr");
    let f32s = |name: &'static str, v: Vec<f32>| AnyChannel::new(name, FlatSamples::F32(v));
    let axis = |v: &[glam::Vec3], k: usize| v.iter().map(|p| p[k]).collect::<Vec<f32>>();
    let mut list = vec![
        f32s("A", vec![1.0; frame.color.len()]),
        f32s("Z", frame.depth.clone()),
        f32s("camera_z.Z", frame.camera_z.clone()),
        AnyChannel::new("id.object", FlatSamples::U32(frame.object_id.clone())),
        AnyChannel::new("id.part", FlatSamples::U32(frame.part_id.clone())),
    ];
    for (k, [c, p, n]) in [
        ["R", "P.X", "N.X"],
        ["G", "P.Y", "N.Y"],
        ["B", "P.Z", "N.Z"],
    ]
    .into_iter()
    .enumerate()
    {
        list.push(f32s(c, axis(&frame.color, k)));
        list.push(f32s(p, axis(&frame.position, k)));
        list.push(f32s(n, axis(&frame.normal, k)));
    }
    let copy = Layer::new(
        (frame.width as usize, frame.height as usize),
        LayerAttributes::default(),
        Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::Tiles(Vec2(64, 64)),
            line_order: LineOrder::Increasing,
        },
        AnyChannels::sort(SmallVec::from_vec(list)),
    );
    Image::from_layer(copy).write().to_file(&theirs).unwrap();
    let (a, b) = (channels(&ours), channels(&theirs));
    assert_eq!(a.len(), 14);
    for ((na, sa), (nb, sb)) in a.iter().zip(&b) {
        assert_eq!(na, nb);
        assert_eq!(bits(sa), bits(sb), "channel {na}");
    }
    // Faster than the exr crate's deflate, so not its bytes; smaller than raw samples.
    let (size_ours, size_theirs) = (
        std::fs::metadata(&ours).unwrap().len(),
        std::fs::metadata(&theirs).unwrap().len(),
    );
    assert!(size_ours < 14 * 4 * frame.color.len() as u64 * 3 / 4);
    assert!(
        size_ours < size_theirs * 3 / 2,
        "{size_ours} vs {size_theirs}"
    );
    // The same bytes on one thread and on three.
    let bytes_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let path = dir.path().join(format!("t{threads}.exr"));
        pool.install(|| write_frame(&frame, dir.path(), &format!("t{threads}"), ExrContent::All))
            .unwrap();
        std::fs::read(path).unwrap()
    };
    let one = bytes_on(1);
    assert!(one == std::fs::read(&ours).unwrap(), "bytes differ");
    assert!(one == bytes_on(3), "bytes differ on 3 threads");
    // Many blocks (30 tiles), more than one thread's share of them at a time.
    let (width, height) = (131usize, 600usize);
    let noise: Vec<f32> = (0..width * height)
        .map(|i| (hash_u32(i as u32) % 1000) as f32 * 0.01)
        .collect();
    let tall_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let path = dir.path().join(format!("tall{threads}.exr"));
        let list = vec![AnyChannel::new("Y", FlatSamples::F32(noise.clone()))];
        pool.install(|| write_exr_channels(&path, width as u32, height as u32, list))
            .unwrap();
        std::fs::read(path).unwrap()
    };
    assert!(tall_on(1) == tall_on(3), "bytes differ on 3 threads");
    assert!(tall_on(1) == tall_on(16), "bytes differ on 16 threads");
}

#[test]
fn exrs_read_from_the_frame_are_the_bytes_of_its_copied_channels() {
    use seethru::io::exr_zip::{Plane, write_planes};
    use seethru::io::frame_files::{write_view_exr, write_view_exr_copied};
    // Every content, a partial last block (61 lines), awkward samples in every AOV.
    let mut frame = rendered();
    assert_ne!(frame.height % 16, 0);
    for (i, id) in frame.part_id.iter_mut().enumerate() {
        *id = hash_u32(i as u32);
    }
    frame.depth[3] = f32::INFINITY;
    frame.color[5].y = -0.0;
    let dir = tempfile::tempdir().unwrap();
    for content in [
        ExrContent::None,
        ExrContent::Colour,
        ExrContent::Lean,
        ExrContent::All,
    ] {
        let (ours, twin) = (dir.path().join("ours.exr"), dir.path().join("twin.exr"));
        let _ = std::fs::remove_file(&ours);
        let _ = std::fs::remove_file(&twin);
        write_view_exr(&frame, &ours, content).unwrap();
        write_view_exr_copied(&frame, &twin, content).unwrap();
        if content == ExrContent::None {
            assert!(!ours.exists() && !twin.exists());
            continue;
        }
        let (a, b) = (std::fs::read(&ours).unwrap(), std::fs::read(&twin).unwrap());
        assert!(
            a == b,
            "{content:?}: {} bytes vs the twin's {}",
            a.len(),
            b.len()
        );
    }
    // Many blocks (38), two planes, on 1 and 3 threads: the owned-channel writer's bytes.
    let (width, height) = (131usize, 600usize);
    let noise: Vec<f32> = (0..width * height)
        .map(|i| (hash_u32(i as u32) % 1000) as f32 * 0.01)
        .collect();
    let ids: Vec<u32> = (0..width * height)
        .map(|i| hash_u32(7 + i as u32) % 5)
        .collect();
    let twin = dir.path().join("tall_twin.exr");
    let list = vec![
        AnyChannel::new("Y", FlatSamples::F32(noise.clone())),
        AnyChannel::new("id", FlatSamples::U32(ids.clone())),
    ];
    write_exr_channels(&twin, width as u32, height as u32, list).unwrap();
    let twin = std::fs::read(twin).unwrap();
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut bytes = std::io::Cursor::new(Vec::new());
        let planes = [("id", Plane::U32(&ids)), ("Y", Plane::F32(&noise))];
        pool.install(|| write_planes(width, height, &planes, &mut bytes))
            .unwrap();
        assert!(
            bytes.into_inner() == twin,
            "bytes differ on {threads} threads"
        );
    }
    // A plane of the wrong length, or two channels of one name: refused, not written.
    let short = &noise[1..];
    let refused = [
        vec![("Y", Plane::F32(short))],
        vec![("Y", Plane::F32(&noise)), ("Y", Plane::U32(&ids))],
    ];
    for planes in refused {
        let mut bytes = std::io::Cursor::new(Vec::new());
        let error = write_planes(width, height, &planes, &mut bytes).unwrap_err();
        assert!(error.to_string().contains('Y') || error.to_string().contains("duplicate"));
    }
}

/// The R, G, B bits of an EXR's channels, for comparing the colour of two files.
fn rgb_bits(path: &std::path::Path) -> Vec<Vec<u32>> {
    let read = channels(path);
    ["R", "G", "B"]
        .iter()
        .map(|name| bits(&read.iter().find(|(n, _)| n == name).unwrap().1))
        .collect()
}

/// Sorted channel names of an EXR.
fn channel_names(path: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = channels(path).into_iter().map(|(n, _)| n).collect();
    names.sort();
    names
}

#[test]
fn capture_and_score_write_the_exrs_their_exr_flag_names() {
    use common::refusal::{listing, run_in};
    let dir = common::refusal::scratch("", &[]);
    let capture = |exr: &str| {
        let out = format!("cap_{exr}");
        let args = [
            "capture",
            "scene.toml",
            "--out",
            &out,
            "--depth",
            "--spp",
            "1",
            "--exr",
            exr,
        ];
        let (code, err) = run_in(dir.path(), &args);
        assert_eq!(code, 0, "{args:?}: {err}");
        let top: Vec<String> = listing(&dir.path().join(&out));
        let files: Vec<String> = serde_json::from_str::<serde_json::Value>(
            &std::fs::read_to_string(dir.path().join(&out).join("capture.json")).unwrap(),
        )
        .unwrap()["files"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap().to_string())
            .collect();
        // capture.json lists exactly the method's image and JSON files that are there.
        for f in &files {
            assert!(top.contains(f), "{exr}: {f} listed, not written");
        }
        let exrs: Vec<&String> = top.iter().filter(|f| f.ends_with(".exr")).collect();
        for f in exrs.iter().filter(|f| !f.contains('/')) {
            assert!(
                files.contains(f) || *f == "depth.exr",
                "{exr}: {f} not listed"
            );
        }
        (
            dir.path().join(&out),
            exrs.into_iter().cloned().collect::<Vec<_>>(),
        )
    };
    let (all, all_exrs) = capture("all");
    assert_eq!(
        all_exrs,
        ["back.exr", "depth.exr", "frontal.exr", "truth/truth.exr"]
    );
    let (colour, colour_exrs) = capture("colour");
    assert_eq!(colour_exrs, ["back.exr", "frontal.exr", "truth/truth.exr"]);
    let (_, none_exrs) = capture("none");
    assert!(none_exrs.is_empty(), "{none_exrs:?}");
    // The truth: every AOV with `all`, the same colour bits alone with `colour`.
    let truth = |d: &std::path::Path| d.join("truth/truth.exr");
    assert_eq!(channel_names(&truth(&all)).len(), 14);
    assert_eq!(channel_names(&truth(&colour)), ["A", "B", "G", "R"]);
    assert_eq!(rgb_bits(&truth(&colour)), rgb_bits(&truth(&all)));
    for view in ["frontal.exr", "back.exr"] {
        assert_eq!(rgb_bits(&colour.join(view)), rgb_bits(&all.join(view)));
    }

    // score: the views' EXRs as `run --exr` writes them. A map showing one frontal pixel.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(all.join("capture.json")).unwrap()).unwrap();
    let [w, h] = [0, 1].map(|i| manifest["display_resolution_px"][i].as_u64().unwrap() as usize);
    let xy: Vec<f32> = (0..w * h).flat_map(|_| [10.0f32, 12.0]).collect();
    seethru::io::display_map::write_npy_f32(&dir.path().join("m.npy"), &[h, w, 2], &xy).unwrap();
    let score = |exr: &str| {
        let out = format!("score_{exr}");
        let args = [
            "score", "cap_all", "--map", "m.npy", "--out", &out, "--exr", exr,
        ];
        let (code, err) = run_in(dir.path(), &args);
        assert_eq!(code, 0, "{args:?}: {err}");
        dir.path().join(out)
    };
    let (all, colour, none) = (score("all"), score("colour"), score("none"));
    for view in ["truth", "seethru", "occluded", "display"] {
        let file = format!("{view}.exr");
        assert_eq!(channel_names(&all.join(&file)).len(), 14, "{view}");
        assert_eq!(channel_names(&colour.join(&file)), ["A", "B", "G", "R"]);
        assert_eq!(rgb_bits(&colour.join(&file)), rgb_bits(&all.join(&file)));
        assert!(!none.join(&file).exists(), "{view}");
        assert_eq!(
            std::fs::read(none.join(format!("{view}.png"))).unwrap(),
            std::fs::read(all.join(format!("{view}.png"))).unwrap()
        );
    }
}

#[test]
fn sequence_writes_colour_exr_frames_and_refuses_exr_where_it_writes_none() {
    use common::refusal::{refused, run_in};
    let dir = common::refusal::scratch("", &[]);
    let quick = ["--duration", "0.05", "--width", "24", "--fps", "40"];
    let frames = |exr: &str| {
        let out = format!("seq_{exr}");
        let mut args = vec!["sequence", "scene.toml", "--out", &out, "--frames", "exr"];
        args.extend(quick);
        args.extend(["--exr", exr]);
        let (code, err) = run_in(dir.path(), &args);
        assert_eq!(code, 0, "{args:?}: {err}");
        dir.path().join(out).join("latency_0ms/frames")
    };
    let (all, colour) = (frames("all"), frames("colour"));
    let mut names: Vec<String> = std::fs::read_dir(&all)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into())
        .collect();
    names.sort();
    assert_eq!(names.len(), 4, "{names:?}");
    for name in &names {
        assert_eq!(channel_names(&all.join(name)).len(), 14, "{name}");
        assert_eq!(channel_names(&colour.join(name)), ["A", "B", "G", "R"]);
        assert_eq!(rgb_bits(&colour.join(name)), rgb_bits(&all.join(name)));
    }
    // Without --capture or --frames exr nothing is an EXR: the flag is refused, as is
    // --exr none beside --frames exr.
    let mut args = vec!["sequence", "scene.toml", "--out", "x", "--exr", "all"];
    args.extend(quick);
    refused(
        dir.path(),
        &args,
        1,
        &["--exr", "--capture or --frames exr"],
    );
    let mut args = vec!["sequence", "scene.toml", "--out", "x", "--frames", "exr"];
    args.extend(quick);
    args.extend(["--exr", "none"]);
    refused(dir.path(), &args, 1, &["--exr none", "--frames png"]);
    assert!(!dir.path().join("x").exists());
}

#[test]
fn a_run_writes_the_same_files_on_any_thread_count_and_views_as_written_alone() {
    // `run` writes each view as soon as it is made, beside the next renders and the metrics,
    // and takes truth's compressed blocks for occluded and seethru where their samples are
    // truth's: neither the order nor the reuse may show in the files.
    let dir = tempfile::tempdir().unwrap();
    let das = common::repo_path("scenes/das.toml");
    let run = |threads: &str| {
        let out = dir.path().join(format!("t{threads}"));
        let (ok, _, err) = common::seethru(&[
            "run",
            das.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--width",
            "192",
            "--frontal-width",
            "192",
            "--back-width",
            "64",
            "--threads",
            threads,
        ]);
        assert!(ok, "{err}");
        out
    };
    let (one, three) = (run("1"), run("3"));
    let mut names: Vec<String> = std::fs::read_dir(&one)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into())
        .collect();
    names.sort();
    assert!(names.len() >= 20, "{names:?}");
    for name in names.iter().filter(|n| *n != "run.json") {
        let (a, b) = (one.join(name), three.join(name));
        assert!(
            std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
            "{name} differs between 1 and 3 threads"
        );
    }
    // Every view's EXR holds that view (its colour is its PNG's, written from the frame on
    // its own) and is the file its channels give written alone (the exr crate's block
    // extraction, seethru's ZIP).
    for view in ["truth", "occluded", "seethru", "frontal", "back", "display"] {
        let path = one.join(format!("{view}.exr"));
        let rgb = rgb_bits(&path);
        let srgb: Vec<u8> = (0..rgb[0].len())
            .flat_map(|i| {
                let c = [0, 1, 2].map(|k| f32::from_bits(rgb[k][i]));
                seethru::util::color::encode_srgb8(glam::Vec3::from_array(c))
            })
            .collect();
        let png = image::open(one.join(format!("{view}.png")))
            .unwrap()
            .to_rgb8();
        assert!(
            srgb == png.into_raw(),
            "{view}.exr does not hold {view}.png's colour"
        );
        let (width, height) = seethru::io::frame_files::exr_size(&path).unwrap();
        let list = channels(&path)
            .into_iter()
            .map(|(name, samples)| AnyChannel::new(name.as_str(), samples))
            .collect();
        let alone = dir.path().join(format!("{view}_alone.exr"));
        write_exr_channels(&alone, width, height, list).unwrap();
        assert!(
            std::fs::read(&path).unwrap() == std::fs::read(&alone).unwrap(),
            "{view}.exr is not the file its channels make"
        );
    }
}
