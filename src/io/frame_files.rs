//! Frames as files: colour PNG (sRGB), id false-colour PNG, and one EXR with every AOV;
//! and the EXR read back. Every file is written whole or not at all ([`write_atomically`]).

use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::*;
use glam::Vec3;

use crate::io::atomic::write_atomically;
use crate::render::frame::Frame;
use crate::util::color::encode_srgb8;
use crate::util::sampling::hash_u32;

/// Writes an RGB8 buffer as PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: Vec<u8>) -> Result<()> {
    let img =
        image::RgbImage::from_raw(width, height, rgb).context("image buffer has the wrong size")?;
    write_atomically(path, |tmp| {
        Ok(img.save_with_format(tmp, image::ImageFormat::Png)?)
    })
}

/// The colour AOV as an 8-bit sRGB PNG (clamped to [0, 1]).
pub fn write_color_png(frame: &Frame, path: &Path) -> Result<()> {
    let rgb = frame.color.iter().flat_map(|&c| encode_srgb8(c)).collect();
    write_png(path, frame.width, frame.height, rgb)
}

/// A stable, well-separated colour for an id; black for 0 (sky).
pub fn id_color(id: u32) -> [u8; 3] {
    if id == 0 {
        return [0, 0, 0];
    }
    let h = hash_u32(id);
    [
        (h & 0xff) as u8 | 0x30,
        ((h >> 8) & 0xff) as u8 | 0x30,
        ((h >> 16) & 0xff) as u8 | 0x30,
    ]
}

/// Object ids in false colour, for looking at; part ids modulate the brightness.
pub fn write_id_png(frame: &Frame, path: &Path) -> Result<()> {
    let rgb = frame
        .object_id
        .iter()
        .zip(&frame.part_id)
        .flat_map(|(&o, &p)| id_color(o).map(|c| (c as u32 * (8 - p % 4) / 8) as u8))
        .collect();
    write_png(path, frame.width, frame.height, rgb)
}

fn vec_channels(name: &str, values: &[Vec3], axes: [&str; 3]) -> [AnyChannel<FlatSamples>; 3] {
    [0, 1, 2].map(|i| {
        AnyChannel::new(
            format!("{name}.{}", axes[i]).as_str(),
            FlatSamples::F32(values.iter().map(|v| v[i]).collect()),
        )
    })
}

/// Every AOV in one EXR: `color.{R,G,B}`, `depth.Z`, `camera_z.Z`, `position.{X,Y,Z}`,
/// `normal.{X,Y,Z}` (f32) and `object_id.id`, `part_id.id` (u32).
pub fn write_exr(frame: &Frame, path: &Path) -> Result<()> {
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    channels.extend(vec_channels("color", &frame.color, ["R", "G", "B"]));
    channels.push(AnyChannel::new(
        "depth.Z",
        FlatSamples::F32(frame.depth.clone()),
    ));
    channels.push(AnyChannel::new(
        "camera_z.Z",
        FlatSamples::F32(frame.camera_z.clone()),
    ));
    channels.extend(vec_channels("position", &frame.position, ["X", "Y", "Z"]));
    channels.extend(vec_channels("normal", &frame.normal, ["X", "Y", "Z"]));
    channels.push(AnyChannel::new(
        "object_id.id",
        FlatSamples::U32(frame.object_id.clone()),
    ));
    channels.push(AnyChannel::new(
        "part_id.id",
        FlatSamples::U32(frame.part_id.clone()),
    ));
    write_exr_channels(path, frame.width, frame.height, channels)
}

/// Writes named channels (`layer.channel`) of a `width`×`height` image as one EXR.
pub fn write_exr_channels(
    path: &Path,
    width: u32,
    height: u32,
    channels: Vec<AnyChannel<FlatSamples>>,
) -> Result<()> {
    // Run-length encoding: lossless and several times faster to write than ZIP (which
    // took longer than rendering the views), at about 1.7× ZIP's file size.
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::named("seethru"),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let image = Image::from_layer(layer);
    write_atomically(path, |tmp| Ok(image.write().to_file(tmp)?))
}

/// Reads an EXR written by [`write_exr`] back into a frame.
pub fn read_exr(path: &Path) -> Result<Frame> {
    let image = read_first_flat_layer_from_file(path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let layer = &image.layer_data;
    let (width, height) = (layer.size.width() as u32, layer.size.height() as u32);
    let find = |name: &str| -> Result<&FlatSamples> {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .map(|c| &c.sample_data)
            .with_context(|| format!("{}: no channel `{name}`", path.display()))
    };
    let f32s = |name: &str| -> Result<Vec<f32>> {
        match find(name)? {
            FlatSamples::F32(v) => Ok(v.clone()),
            _ => bail!("{}: channel `{name}` is not f32", path.display()),
        }
    };
    let u32s = |name: &str| -> Result<Vec<u32>> {
        match find(name)? {
            FlatSamples::U32(v) => Ok(v.clone()),
            _ => bail!("{}: channel `{name}` is not u32", path.display()),
        }
    };
    let vec3s = |name: &str, axes: [&str; 3]| -> Result<Vec<Vec3>> {
        let [x, y, z] = [
            f32s(&format!("{name}.{}", axes[0]))?,
            f32s(&format!("{name}.{}", axes[1]))?,
            f32s(&format!("{name}.{}", axes[2]))?,
        ];
        Ok(x.iter()
            .zip(&y)
            .zip(&z)
            .map(|((&x, &y), &z)| Vec3::new(x, y, z))
            .collect())
    };
    Ok(Frame {
        width,
        height,
        color: vec3s("color", ["R", "G", "B"])?,
        depth: f32s("depth.Z")?,
        camera_z: f32s("camera_z.Z")?,
        position: vec3s("position", ["X", "Y", "Z"])?,
        normal: vec3s("normal", ["X", "Y", "Z"])?,
        object_id: u32s("object_id.id")?,
        part_id: u32s("part_id.id")?,
    })
}

/// Writes `<name>.png`, `<name>_ids.png` and `<name>.exr` into `dir`.
pub fn write_frame(frame: &Frame, dir: &Path, name: &str) -> Result<()> {
    write_color_png(frame, &dir.join(format!("{name}.png")))?;
    write_id_png(frame, &dir.join(format!("{name}_ids.png")))?;
    write_exr(frame, &dir.join(format!("{name}.exr")))
}
