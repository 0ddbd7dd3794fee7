//! An image read for comparison, as layers: a PNG is one `colour` layer of 8-bit sRGB; an
//! EXR's channels are grouped by name (`R`, `G`, `B` → `colour`, `P.X` → `P`). Apart from the
//! diff itself (measure/image_diff.rs): reading the files, their size limits and errors that
//! name the file are their own work, done before any metric.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use exr::prelude::FlatSamples;

use crate::scene::limits::{MAX_PIXELS, MAX_RESOLUTION};
use crate::util::input_file::not_a_file;

/// What the values of a layer are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerKind {
    /// 8-bit sRGB colour, [0, 255] per channel (a PNG).
    Srgb8,
    /// Linear RGB colour, [0, ∞) per channel (an EXR's `R`, `G`, `B`).
    LinearColour,
    /// Any other channels (depth in m, positions, normals, ids, masks).
    Data,
}

/// One layer of an image: channels that belong together (`P.X`, `P.Y`, `P.Z` → `P`).
pub struct Layer {
    pub name: String,
    pub kind: LayerKind,
    /// Channel names as in the file.
    pub channels: Vec<String>,
    /// Values per channel, row-major, `width × height` each.
    pub values: Vec<Vec<f64>>,
}

/// An image read for comparison.
pub struct Picture {
    pub path: PathBuf,
    pub width: u32,
    pub height: u32,
    pub layers: Vec<Layer>,
}

impl Picture {
    pub fn layer(&self, name: &str) -> Option<&Layer> {
        self.layers.iter().find(|l| l.name == name)
    }

    pub fn layer_names(&self) -> Vec<&str> {
        self.layers.iter().map(|l| l.name.as_str()).collect()
    }
}

/// The layer a channel of an EXR belongs to: `R`, `G`, `B` form `colour`; `P.X` belongs to `P`.
fn layer_of(channel: &str) -> &str {
    match channel {
        "R" | "G" | "B" => "colour",
        _ => channel.rsplit_once('.').map_or(channel, |(layer, _)| layer),
    }
}

fn check_size(width: usize, height: usize) -> Result<()> {
    if width == 0
        || height == 0
        || width > MAX_RESOLUTION as usize
        || height > MAX_RESOLUTION as usize
        || (width as u64) * (height as u64) > MAX_PIXELS
    {
        bail!(
            "the image is {width}×{height}: each side must be in [1, {MAX_RESOLUTION}], at most {MAX_PIXELS} pixels"
        );
    }
    Ok(())
}

/// Reads a PNG (one `colour` layer, 8-bit sRGB) or an EXR (its channels grouped into layers).
/// Errors name the file.
pub fn read_picture(path: &Path) -> Result<Picture> {
    crate::util::input_file::note_input(path);
    if let Some(why) = not_a_file(path) {
        bail!("cannot read {}: {why}", path.display());
    }
    let is_exr = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let picture = if is_exr {
        read_exr_layers(path)
    } else {
        read_png(path)
    };
    picture.with_context(|| format!("cannot read {}", path.display()))
}

fn read_png(path: &Path) -> Result<Picture> {
    let reader = image::ImageReader::open(path)?
        .with_guessed_format()
        .context("not a readable image")?;
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| anyhow::anyhow!("not a readable PNG: {e}"))?;
    check_size(w as usize, h as usize)?;
    let image = image::ImageReader::open(path)?
        .with_guessed_format()?
        .decode()
        .map_err(|e| anyhow::anyhow!("not a readable PNG: {e}"))?
        .to_rgb8();
    let values = (0..3)
        .map(|c| image.pixels().map(|p| p[c] as f64).collect())
        .collect();
    Ok(Picture {
        path: path.to_path_buf(),
        width: w,
        height: h,
        layers: vec![Layer {
            name: "colour".into(),
            kind: LayerKind::Srgb8,
            channels: ["R", "G", "B"].map(String::from).to_vec(),
            values,
        }],
    })
}

fn read_exr_layers(path: &Path) -> Result<Picture> {
    let file = std::fs::File::open(path)?;
    let meta = exr::meta::MetaData::read_from_unbuffered(file, false)
        .map_err(|e| anyhow::anyhow!("not a readable EXR: {e}"))?;
    let header = meta.headers.first().context("the file has no layer")?;
    check_size(header.layer_size.width(), header.layer_size.height())?;
    let image = crate::io::frame_files::read_first_layer(|r| r.from_file(path))?;
    let layer = &image.layer_data;
    let (width, height) = (layer.size.width() as u32, layer.size.height() as u32);
    let mut layers: Vec<Layer> = Vec::new();
    for channel in &layer.channel_data.list {
        let name = channel.name.to_string();
        let values: Vec<f64> = match &channel.sample_data {
            FlatSamples::F16(v) => v.iter().map(|x| x.to_f64()).collect(),
            FlatSamples::F32(v) => v.iter().map(|&x| x as f64).collect(),
            FlatSamples::U32(v) => v.iter().map(|&x| x as f64).collect(),
        };
        let layer_name = layer_of(&name).to_string();
        match layers.iter_mut().find(|l| l.name == layer_name) {
            Some(l) => {
                l.channels.push(name);
                l.values.push(values);
            }
            None => layers.push(Layer {
                kind: if layer_name == "colour" {
                    LayerKind::LinearColour
                } else {
                    LayerKind::Data
                },
                name: layer_name,
                channels: vec![name],
                values: vec![values],
            }),
        }
    }
    // The colour channels in R, G, B order (EXR sorts channels by name: B, G, R).
    for l in layers
        .iter_mut()
        .filter(|l| l.kind == LayerKind::LinearColour)
    {
        let mut pairs: Vec<(String, Vec<f64>)> =
            l.channels.drain(..).zip(l.values.drain(..)).collect();
        pairs.sort_by_key(|(n, _)| ["R", "G", "B"].iter().position(|c| c == n));
        (l.channels, l.values) = pairs.into_iter().unzip();
        if l.channels.len() != 3 {
            bail!(
                "the colour layer has channels {} (expected R, G and B)",
                l.channels.join(", ")
            );
        }
    }
    Ok(Picture {
        path: path.to_path_buf(),
        width,
        height,
        layers,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each side in [1, MAX_RESOLUTION] and the area at most MAX_PIXELS, every bound
    /// inclusive, each rule refusing alone.
    #[test]
    fn picture_sizes_are_checked_at_their_bounds() {
        let max = MAX_RESOLUTION as usize;
        let tall = (MAX_PIXELS / u64::from(MAX_RESOLUTION)) as usize;
        for (w, h) in [(1, 1), (max, 1), (1, max), (max, tall), (tall, max)] {
            assert!(check_size(w, h).is_ok(), "{w}×{h}");
        }
        for (w, h) in [(0, 1), (1, 0), (max + 1, 1), (1, max + 1), (max, tall + 1)] {
            let e = check_size(w, h).unwrap_err().to_string();
            assert!(e.contains(&format!("{w}×{h}")), "{e}");
        }
    }

    /// EXR stores channels sorted by name (B, G, R); the colour layer reads back as R, G, B.
    #[test]
    fn an_exr_colour_layer_reads_as_r_g_b() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.exr");
        let channel =
            |name: &str, v: f32| exr::prelude::AnyChannel::new(name, FlatSamples::F32(vec![v; 2]));
        let channels = vec![channel("R", 1.0), channel("G", 2.0), channel("B", 3.0)];
        crate::io::frame_files::write_exr_channels(&path, 2, 1, channels).unwrap();
        let picture = read_picture(&path).unwrap();
        let colour = picture.layers.iter().find(|l| l.name == "colour").unwrap();
        assert_eq!(colour.channels, ["R", "G", "B"]);
        assert_eq!(colour.values, [vec![1.0; 2], vec![2.0; 2], vec![3.0; 2]]);
    }

    #[test]
    fn channels_group_into_layers() {
        assert_eq!(layer_of("R"), "colour");
        assert_eq!(layer_of("P.X"), "P");
        assert_eq!(layer_of("camera_z.Z"), "camera_z");
        assert_eq!(layer_of("Z"), "Z");
    }
}
