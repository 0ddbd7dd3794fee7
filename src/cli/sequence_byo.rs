//! `sequence --capture DIR` and `sequence --maps DIR`: one folder per display refresh in
//! `seethru capture`'s format (so a method written for one capture reads one frame's folder),
//! and one map per refresh scored as the sequence scores its own compensation.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use anyhow::{Result, bail};
use seethru::io::atomic::write_text;
use seethru::io::frame_files::ExrContent;
use seethru::measure::capture_files::write_capture_folder;
use seethru::measure::sequence::FrameImages;
use seethru::system::capture::check_display_input;
use seethru::system::sequence::byo::NamedMap;
use seethru::system::sequence::timeline::Timeline;
use serde_json::{Value, json};

use crate::cli::score::load_map;

/// The folder (in `--capture`) and map stem (in `--maps`) of the refresh first shown at
/// displayed frame `frame`.
pub fn frame_name(frame: usize) -> String {
    format!("frame_{frame:05}")
}

/// The displayed frames that start a refresh (each has a folder and a map), with the refresh.
fn refresh_starts(timeline: &Timeline) -> Vec<(usize, i64)> {
    let mut last = None;
    let mut starts = Vec::new();
    for k in 0..timeline.frames() {
        let r = timeline.times(k).refresh;
        if last != Some(r) {
            starts.push((k, r));
            last = Some(r);
        }
    }
    starts
}

/// Reads `DIR/frame_NNNNN.npy` (or `.exr`) for every refresh, checking each against the
/// display's size before anything is rendered; the fingerprint is checked per refresh.
pub fn load_maps(
    dir: &Path,
    timeline: &Timeline,
    display_size: [u32; 2],
) -> Result<Arc<BTreeMap<i64, NamedMap>>> {
    if !dir.is_dir() {
        bail!(
            "--maps {}: not a folder (it holds frame_NNNNN.npy or .exr, one per refresh)",
            dir.display()
        );
    }
    let mut maps = BTreeMap::new();
    for (frame, refresh) in refresh_starts(timeline) {
        let stem = frame_name(frame);
        let Some(path) = ["npy", "exr"]
            .iter()
            .map(|ext| dir.join(format!("{stem}.{ext}")))
            .find(|p| p.exists())
        else {
            bail!(
                "--maps {}: no map for frame {frame} ({stem}.npy or {stem}.exr)",
                dir.display()
            );
        };
        let map = load_map(&path)?;
        let file = path.display().to_string();
        // The fingerprint is the refresh's, known once it is rendered: checked then.
        let own = map.fingerprint.clone().unwrap_or_default();
        check_display_input(display_size, None, &own, Some(&map), None)
            .map_err(|e| anyhow::anyhow!("{file} (frame {frame}): {e}"))?;
        maps.insert(refresh, NamedMap { file, frame, map });
    }
    Ok(Arc::new(maps))
}

/// One row of `frames.json`: which folder a displayed frame shows, and its times.
pub fn index_row(f: &FrameImages, folder: &str, world_from_obstacle: Value) -> Value {
    let t = &f.record.times;
    json!({
        "frame": f.record.frame,
        "refresh": t.refresh,
        "folder": folder,
        "capture_time_s": t.capture,
        "head_sample_time_s": t.head,
        "refresh_time_s": t.refresh_time,
        "display_time_s": t.display,
        "world_from_obstacle_at_capture": world_from_obstacle,
    })
}

/// Writes the refresh's folder when this frame starts one; returns the folder shown.
pub fn write_frame(
    dir: &Path,
    f: &FrameImages,
    command: &Value,
    last_folder: &mut String,
    exr: ExrContent,
) -> Result<Value> {
    let mut world_from_obstacle = Value::Null;
    if let Some(c) = &f.capture {
        *last_folder = frame_name(f.record.frame);
        write_capture_folder(
            &dir.join(last_folder.as_str()),
            c,
            ("sequence_command.json", command),
            exr,
        )?;
        world_from_obstacle = c.calibration["obstacle_frame"]["world_from_obstacle"].clone();
    }
    Ok(index_row(f, last_folder, world_from_obstacle))
}

/// `frames.json`, written last: a folder holding it holds a finished sequence capture.
pub fn write_index(dir: &Path, rows: Vec<Value>) -> Result<()> {
    // Rows of held refreshes carry the pose of the folder they show.
    let mut pose = Value::Null;
    let rows: Vec<Value> = rows
        .into_iter()
        .map(|mut r| {
            if r["world_from_obstacle_at_capture"].is_null() {
                r["world_from_obstacle_at_capture"] = pose.clone();
            } else {
                pose = r["world_from_obstacle_at_capture"].clone();
            }
            r
        })
        .collect();
    write_text(
        &dir.join("frames.json"),
        &serde_json::to_string_pretty(&json!({
            "frames": rows,
            "layout": "one folder per display refresh, frame_NNNNN/ named by the first displayed frame that shows it, holding exactly what seethru capture writes (frontal.png/.exr, back.png/.exr, head.json, calibration.json, capture.json with the refresh's fingerprint, truth/); every displayed frame's row names the folder it shows",
            "times": "capture_time_s: the frontal image; head_sample_time_s: the back image behind the head estimate; refresh_time_s: when the display took the image; display_time_s: when the frame is looked at and measured (truth/ is of that instant)",
            "world": "the rig is fixed in the obstacle frame, but the vehicle moves in the world: each folder's calibration.json is in the world frame at its capture time (the display at the refresh time with --reproject); world_from_obstacle_at_capture is that pose, rows of 4",
            "head": "head.json is the estimate the compensation used (predicted to the refresh time with --predict); detection is not recorded in a sequence",
            "maps": "sequence --maps DIR reads DIR/frame_NNNNN.npy (or .exr) for every folder here, with its <map>.json sidecar's capture_fingerprint checked against the folder's",
        }))?,
    )
}
