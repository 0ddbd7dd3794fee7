//! Frames as files: colour PNG (sRGB), id false-colour PNG, and one EXR with every AOV (or
//! only the colour, or none: [`ExrContent`]); and the EXR read back. Every file is written
//! whole or not at all ([`write_atomically`]).

use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::*;
use glam::Vec3;

use crate::io::atomic::write_atomically;
use crate::io::exr_zip;
use crate::render::frame::Frame;
use crate::render::frame_over::FrameView;
use crate::scene::limits::{MAX_COORDINATE, MAX_PIXELS, MAX_RESOLUTION};
use crate::util::color::encode_srgb8;
use crate::util::number::short;
use crate::util::sampling::hash_u32;

/// Writes an RGB8 buffer as PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: Vec<u8>) -> Result<()> {
    let img =
        image::RgbImage::from_raw(width, height, rgb).context("image buffer has the wrong size")?;
    write_atomically(
        path,
        |file| Ok(img.write_to(file, image::ImageFormat::Png)?),
    )
}

/// The colour AOV as an 8-bit sRGB PNG (clamped to [0, 1]; [`encode_srgb8`]).
/// A frame from a camera that codes its image ([`crate::geometry::sensor::Coding`]) is its
/// codes instead: 8 bits as they are, 10 or 12 bits in a 16-bit PNG, each code scaled by
/// 65535 / its top code (rounded: exact both ways).
pub fn write_color_png<'a>(frame: impl Into<FrameView<'a>>, path: &Path) -> Result<()> {
    let frame = frame.into();
    if let FrameView::Whole(whole) = frame
        && let Some(exposure) = whole.exposure.filter(|e| e.coding.is_some())
    {
        return write_codes_png(whole, &exposure, path);
    }
    let (w, h) = (frame.width(), frame.height());
    let mut rgb = vec![0; 3 * w as usize * h as usize];
    let mut out = rgb.chunks_exact_mut(3);
    for y in 0..h {
        for run in frame.row(|f| &f.color, y) {
            for (&c, rgb) in run.iter().zip(&mut out) {
                rgb.copy_from_slice(&encode_srgb8(c));
            }
        }
    }
    write_png(path, w, h, rgb)
}

/// A coded camera's frame as its codes ([`write_color_png`]).
fn write_codes_png(
    frame: &Frame,
    exposure: &crate::geometry::sensor::Exposure,
    path: &Path,
) -> Result<()> {
    let coding = exposure.coding.expect("a coded frame");
    let codes = frame
        .color
        .iter()
        .flat_map(|c| c.to_array())
        .map(|v| f64::from(exposure.code(v)));
    if coding.bits == 8 {
        return write_png(
            path,
            frame.width,
            frame.height,
            codes.map(|v| (v * 255.0).round() as u8).collect(),
        );
    }
    let samples: Vec<u16> = codes.map(|v| (v * 65535.0).round() as u16).collect();
    let img =
        image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(frame.width, frame.height, samples)
            .context("image buffer has the wrong size")?;
    write_atomically(
        path,
        |file| Ok(img.write_to(file, image::ImageFormat::Png)?),
    )
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

/// Object ids in false colour ([`id_color`]), for looking at; part `p` darkens its object's
/// colour to (8 − p mod 4)/8 of it (rounded down), so that neighbouring parts differ.
pub fn write_id_png<'a>(frame: impl Into<FrameView<'a>>, path: &Path) -> Result<()> {
    let frame = frame.into();
    let (w, h) = (frame.width(), frame.height());
    let mut rgb = Vec::with_capacity(3 * w as usize * h as usize);
    for y in 0..h {
        let parts = frame.row(|f| &f.part_id, y);
        for (objects, parts) in frame.row(|f| &f.object_id, y).iter().zip(parts) {
            for (&o, &p) in objects.iter().zip(parts) {
                rgb.extend_from_slice(&id_color(o).map(|c| (c as u32 * (8 - p % 4) / 8) as u8));
            }
        }
    }
    write_png(path, w, h, rgb)
}

/// The EXR channel names of a frame's AOVs, as renderers and compositors name them, so that
/// OpenCV, imageio, Blender and Nuke open the colour without a layer name: the colour is the
/// plain `R`, `G`, `B` (linear, f32) with `A` = 1 of the file's only part, and the AOVs are
/// layers beside it.
pub mod channel {
    /// Colour, linear RGB, and opaque alpha.
    pub const RGBA: [&str; 4] = ["R", "G", "B", "A"];
    /// Distance from the camera's centre along the pixel-centre ray, m (OpenEXR's `Z`: the
    /// distance from the viewer; +∞ for sky).
    pub const Z: &str = "Z";
    /// Depth along the camera's forward axis, m (Blender's `Depth.Z` convention; +∞ for sky).
    pub const CAMERA_Z: &str = "camera_z.Z";
    /// World position, m, world frame (`P` as in Houdini, Arnold and RenderMan).
    pub const P: [&str; 3] = ["P.X", "P.Y", "P.Z"];
    /// Unit normal facing the camera, world frame; for sky the direction back along the ray.
    pub const N: [&str; 3] = ["N.X", "N.Y", "N.Z"];
    /// Object id (u32, 0 = sky) and part id (u32) as in the scene's `ids`.
    pub const OBJECT_ID: &str = "id.object";
    pub const PART_ID: &str = "id.part";
}

fn vec_channels(names: [&str; 3], values: &[Vec3]) -> [AnyChannel<FlatSamples>; 3] {
    [0, 1, 2].map(|i| {
        AnyChannel::new(
            names[i],
            FlatSamples::F32(values.iter().map(|v| v[i]).collect()),
        )
    })
}

/// What the EXR of each view holds (`--exr`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum ExrContent {
    /// No EXR (the PNGs only).
    None,
    /// The colour only: `R`, `G`, `B`, `A` (linear f32), about a quarter of `all`.
    Colour,
    /// The AOVs no other channel gives: `R`, `G`, `B`, `Z`, `N`, `id.object`, `id.part`
    /// (no `A`, every pixel being opaque; no `P` or `camera_z.Z`, which follow from `Z`
    /// and the camera to f32 rounding), about 70 % of `all`: `run`'s default.
    Lean,
    /// Every AOV ([`channel`]): what `seethru measure` reads back.
    #[default]
    All,
}

impl ExrContent {
    /// The files each view gets, for a command's summary line.
    pub fn files(self) -> &'static str {
        match self {
            ExrContent::None => "PNG, ids PNG",
            ExrContent::Colour => "PNG, ids PNG, colour EXR",
            ExrContent::Lean => "PNG, ids PNG, lean EXR",
            ExrContent::All => "PNG, ids PNG, EXR",
        }
    }
}

/// Every AOV in one EXR, under the names of [`channel`].
pub fn write_exr(frame: &Frame, path: &Path) -> Result<()> {
    write_view_exr(frame, path, ExrContent::All)
}

/// The channels of `content` in one EXR at `path`; nothing for [`ExrContent::None`]. The
/// samples are read block by block from the frame's buffers ([`exr_zip::write_planes`]).
pub fn write_view_exr(frame: &Frame, path: &Path, content: ExrContent) -> Result<()> {
    write_view_exr_like(frame, path, content, None)
}

/// The channels of `content` of `frame` as the file's planes ([`exr_zip::Plane`]).
fn view_planes<'a>(
    frame: &'a Frame,
    content: ExrContent,
) -> Vec<(&'static str, exr_zip::Plane<'a>)> {
    use exr_zip::Plane;
    fn vec<'a>(names: [&'static str; 3], values: &'a [Vec3]) -> [(&'static str, Plane<'a>); 3] {
        [0, 1, 2].map(|i| (names[i], Plane::Component(values, i)))
    }
    let [r, g, b, a] = channel::RGBA;
    // The colour in cd/m² where the frame's light is in physical units.
    let colour = |values: &'a [Vec3]| -> [(&'static str, Plane<'a>); 3] {
        match frame.white_cd_m2 {
            Some(white) => {
                [0, 1, 2].map(|i| ([r, g, b][i], Plane::ScaledComponent(values, i, white)))
            }
            None => vec([r, g, b], values),
        }
    };
    let mut planes: Vec<(&str, Plane)> = match content {
        ExrContent::None => return Vec::new(),
        ExrContent::Lean => colour(&frame.color).into(),
        ExrContent::Colour | ExrContent::All => {
            let mut planes: Vec<_> = colour(&frame.color).into();
            planes.push((a, Plane::Constant(1.0)));
            planes
        }
    };
    if matches!(content, ExrContent::Lean | ExrContent::All) {
        planes.push((channel::Z, Plane::F32(&frame.depth)));
        planes.extend(vec(channel::N, &frame.normal));
        planes.push((channel::OBJECT_ID, Plane::U32(&frame.object_id)));
        planes.push((channel::PART_ID, Plane::U32(&frame.part_id)));
    }
    if content == ExrContent::All {
        planes.push((channel::CAMERA_Z, Plane::F32(&frame.camera_z)));
        planes.extend(vec(channel::P, &frame.position));
    }
    planes
}

/// [`write_view_exr`] of a frame whole or rendered over another, reusing the compressed
/// blocks of `like` (another frame's file) where this frame's samples are the same
/// ([`exr_zip::write_planes_like`]: the same bytes).
pub fn write_view_exr_like<'a>(
    frame: impl Into<FrameView<'a>>,
    path: &Path,
    content: ExrContent,
    like: Option<&exr_zip::Zipped>,
) -> Result<()> {
    let over = match frame.into() {
        FrameView::Whole(frame) => {
            return write_planes(frame, path, content, like, false).map(|_| ());
        }
        FrameView::Over(over) => over,
    };
    let (base, patch) = (
        view_planes(over.base(), content),
        view_planes(over.patch(), content),
    );
    let (rect, width) = (over.rect(), over.base().width as usize);
    let planes: Vec<_> = base
        .iter()
        .zip(&patch)
        .map(|((name, base), (_, patch))| {
            let plane = exr_zip::Plane::Over {
                base,
                patch,
                rect,
                width,
            };
            (*name, plane)
        })
        .collect();
    let size = (over.base().width, over.base().height);
    let attributes = layer_attributes(over.base().white_cd_m2);
    write_exr_planes(size, &planes, attributes, path, like, false).map(|_| ())
}

/// [`write_view_exr`], returning the file's blocks for the next file ([`write_view_exr_like`];
/// `None` for [`ExrContent::None`]).
pub fn write_view_exr_keeping<'a>(
    frame: &'a Frame,
    path: &Path,
    content: ExrContent,
) -> Result<Option<exr_zip::Zipped<'a>>> {
    write_planes(frame, path, content, None, true)
}

/// The planes of `content` of `frame` into `path` ([`write_exr_planes`]).
fn write_planes<'a>(
    frame: &'a Frame,
    path: &Path,
    content: ExrContent,
    like: Option<&exr_zip::Zipped>,
    keep: bool,
) -> Result<Option<exr_zip::Zipped<'a>>> {
    let planes = view_planes(frame, content);
    let attributes = layer_attributes(frame.white_cd_m2);
    write_exr_planes(
        (frame.width, frame.height),
        &planes,
        attributes,
        path,
        like,
        keep,
    )
}

/// `planes` of a frame of `size` (width, height) pixels into `path` (nothing without planes:
/// [`ExrContent::None`]), blocks reused from `like`; with `keep`, returns the file's blocks.
fn write_exr_planes<'a>(
    (width, height): (u32, u32),
    planes: &[(&str, exr_zip::Plane<'a>)],
    attributes: LayerAttributes,
    path: &Path,
    like: Option<&exr_zip::Zipped>,
    keep: bool,
) -> Result<Option<exr_zip::Zipped<'a>>> {
    if planes.is_empty() {
        return Ok(None);
    }
    let (width, height) = (width as usize, height as usize);
    let mut zipped = None;
    write_atomically(path, |file| {
        zipped = exr_zip::write_planes_like(width, height, planes, like, keep, attributes, file)?;
        Ok(())
    })?;
    Ok(zipped)
}

/// [`write_view_exr`]'s twin through the exr crate's own block extraction: every channel
/// copied into owned samples, then written by [`write_exr_channels`] (the tests compare the
/// bytes).
pub fn write_view_exr_copied(frame: &Frame, path: &Path, content: ExrContent) -> Result<()> {
    let mut channels = match content {
        ExrContent::None => return Ok(()),
        ExrContent::Lean => colour_channels(frame)[..3].to_vec(),
        ExrContent::Colour | ExrContent::All => colour_channels(frame),
    };
    if matches!(content, ExrContent::Lean | ExrContent::All) {
        channels.push(AnyChannel::new(
            channel::Z,
            FlatSamples::F32(frame.depth.clone()),
        ));
        channels.extend(vec_channels(channel::N, &frame.normal));
        channels.push(AnyChannel::new(
            channel::OBJECT_ID,
            FlatSamples::U32(frame.object_id.clone()),
        ));
        channels.push(AnyChannel::new(
            channel::PART_ID,
            FlatSamples::U32(frame.part_id.clone()),
        ));
    }
    if content == ExrContent::All {
        channels.push(AnyChannel::new(
            channel::CAMERA_Z,
            FlatSamples::F32(frame.camera_z.clone()),
        ));
        channels.extend(vec_channels(channel::P, &frame.position));
    }
    let attributes = layer_attributes(frame.white_cd_m2);
    write_exr_channels_with(path, frame.width, frame.height, channels, attributes)
}

/// The colour (`R`, `G`, `B`, linear f32; cd/m² where the frame's light is in physical
/// units) and an opaque `A`.
fn colour_channels(frame: &Frame) -> Vec<AnyChannel<FlatSamples>> {
    let [r, g, b, a] = channel::RGBA;
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    match frame.white_cd_m2 {
        Some(white) => {
            let scaled: Vec<Vec3> = frame.color.iter().map(|c| *c * white).collect();
            channels.extend(vec_channels([r, g, b], &scaled));
        }
        None => channels.extend(vec_channels([r, g, b], &frame.color)),
    }
    channels.push(AnyChannel::new(
        a,
        FlatSamples::F32(vec![1.0; frame.color.len()]),
    ));
    channels
}

/// The colour alone in one EXR (`R`, `G`, `B`, `A`): what image viewers show.
pub fn write_colour_exr(frame: &Frame, path: &Path) -> Result<()> {
    write_view_exr(frame, path, ExrContent::Colour)
}

/// The lossless compression of every EXR seethru writes: ZIP over tiles of 64×64 pixels
/// (exact for f32 and u32 samples), deflated fast and in parallel by [`exr_zip`]. On das's
/// `run` it took about a third of PIZ's CPU for a folder 14 % larger (docs/guide/performance.md
/// has the figures). Every OpenEXR reader (OpenCV, imageio, Blender, Nuke) reads it.
pub const EXR_COMPRESSION: Compression = exr_zip::COMPRESSION;

/// Writes named channels of a `width`×`height` image as one single-part EXR (no layer name,
/// so that readers of the "first RGBA layer" find plain `R`, `G`, `B`).
pub fn write_exr_channels(
    path: &Path,
    width: u32,
    height: u32,
    channels: Vec<AnyChannel<FlatSamples>>,
) -> Result<()> {
    write_exr_channels_with(path, width, height, channels, LayerAttributes::default())
}

/// The name of the header attribute (f32) that gives a photometric frame's white in cd/m²
/// ([`Frame::white_cd_m2`]): what reading the file back divides its colour by.
pub const WHITE_ATTRIBUTE: &str = "seethru_white_cd_m2";

/// The header of a frame's EXR: where its colour is in cd/m² (a photometric frame, `white`
/// its white), OpenEXR's `whiteLuminance` 1 (the luminance of RGB (1, 1, 1) is 1 cd/m²)
/// and the white in [`WHITE_ATTRIBUTE`].
pub fn layer_attributes(white_cd_m2: Option<f32>) -> LayerAttributes {
    let mut attributes = LayerAttributes::default();
    if let Some(white) = white_cd_m2 {
        attributes.white_luminance = Some(1.0);
        attributes.other.insert(
            Text::from(WHITE_ATTRIBUTE),
            exr::meta::attribute::AttributeValue::F32(white),
        );
    }
    attributes
}

/// [`write_exr_channels`] with the header's `attributes`.
pub fn write_exr_channels_with(
    path: &Path,
    width: u32,
    height: u32,
    channels: Vec<AnyChannel<FlatSamples>>,
    attributes: LayerAttributes,
) -> Result<()> {
    let layer = Layer::new(
        (width as usize, height as usize),
        attributes,
        exr_zip::ENCODING,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let image = Image::from_layer(layer);
    write_atomically(path, |file| Ok(exr_zip::write(&image, file)?))
}

/// Most channels an EXR may have to be read as a frame (seethru writes 14).
const MAX_EXR_CHANNELS: usize = 64;

/// `path` opened for reading if it is a regular file (a device would be read for ever).
fn open_input(path: &Path) -> Result<std::fs::File> {
    crate::util::input_file::note_input(path);
    if let Some(why) = crate::util::input_file::not_a_file(path) {
        bail!("cannot read {}: {why}", path.display());
    }
    std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))
}

/// Reads an EXR written by [`write_exr`] back into a frame. Errors name the file and what is
/// wrong with it: not an EXR, truncated, too large, a channel missing or of the wrong type.
pub fn read_exr(path: &Path) -> Result<Frame> {
    let file = open_input(path)?;
    read_exr_from(std::io::BufReader::new(file), MAX_PIXELS)
        .with_context(|| format!("cannot read {}", path.display()))
}

/// Width and height of the first layer of an EXR, from its header alone.
pub fn exr_size(path: &Path) -> Result<(u32, u32)> {
    let file = open_input(path)?;
    let size = exr::meta::MetaData::read_from_unbuffered(file, false)
        .map_err(anyhow::Error::from)
        .and_then(|meta| {
            let header = meta.headers.first().context("the file has no layer")?;
            Ok(header.layer_size)
        })
        .with_context(|| format!("cannot read {}", path.display()))?;
    Ok((size.width() as u32, size.height() as u32))
}

/// Every channel of an EXR's first layer as flat samples: how seethru reads any EXR (a view,
/// a display map, a diffed image), after its header was checked against the limits.
pub type FirstLayer = Image<Layer<AnyChannels<FlatSamples>>>;

/// Reads the first layer with `from` (a file or a buffered reader), one thread, no deep data.
pub fn read_first_layer(
    from: impl FnOnce(
        exr::image::read::image::ReadImage<
            fn(f64),
            exr::image::read::layers::ReadFirstValidLayer<
                exr::image::read::any_channels::ReadAnyChannels<
                    exr::image::read::samples::ReadFlatSamples,
                >,
            >,
        >,
    ) -> exr::error::Result<FirstLayer>,
) -> Result<FirstLayer> {
    from(
        read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .non_parallel(),
    )
    .map_err(|e| anyhow::anyhow!("invalid or truncated EXR: {e}"))
}

/// Reads an EXR from a reader into a frame, refusing images of more than `max_pixels` before
/// decoding them.
pub fn read_exr_from<R: std::io::Read + std::io::Seek + Send>(
    mut reader: R,
    max_pixels: u64,
) -> Result<Frame> {
    let meta = exr::meta::MetaData::read_from_buffered(&mut reader, false)
        .map_err(|e| anyhow::anyhow!("not a readable EXR: {e}"))?;
    let header = meta.headers.first().context("the file has no layer")?;
    let size = header.layer_size;
    if size.width() == 0
        || size.height() == 0
        || size.width() > MAX_RESOLUTION as usize
        || size.height() > MAX_RESOLUTION as usize
        || (size.width() as u64) * (size.height() as u64) > max_pixels
    {
        bail!(
            "the image is {}×{}: each side must be in [1, {MAX_RESOLUTION}], at most {max_pixels} pixels",
            size.width(),
            size.height()
        );
    }
    if header.channels.list.len() > MAX_EXR_CHANNELS {
        bail!(
            "{} channels, more than the {MAX_EXR_CHANNELS} a frame can have",
            header.channels.list.len()
        );
    }
    reader.seek(std::io::SeekFrom::Start(0))?;
    let image = read_first_layer(|r| r.from_buffered(reader))?;
    let layer = &image.layer_data;
    let (width, height) = (layer.size.width() as u32, layer.size.height() as u32);
    let pixels = width as usize * height as usize;
    let find = |name: &str| -> Result<&FlatSamples> {
        let samples = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .map(|c| &c.sample_data)
            .with_context(|| {
                format!("no channel `{name}` (not written by seethru with option `exr` all?)")
            })?;
        if samples.len() != pixels {
            bail!(
                "channel `{name}` has {} samples for {width}×{height} pixels",
                samples.len()
            );
        }
        Ok(samples)
    };
    let f32s = |name: &str| -> Result<Vec<f32>> {
        match find(name)? {
            FlatSamples::F32(v) => Ok(v.clone()),
            other => bail!("channel `{name}` is {}, expected f32", sample_type(other)),
        }
    };
    let u32s = |name: &str| -> Result<Vec<u32>> {
        match find(name)? {
            FlatSamples::U32(v) => Ok(v.clone()),
            other => bail!("channel `{name}` is {}, expected u32", sample_type(other)),
        }
    };
    let vec3s = |names: [&str; 3]| -> Result<Vec<Vec3>> {
        let [x, y, z] = [f32s(names[0])?, f32s(names[1])?, f32s(names[2])?];
        Ok(x.iter()
            .zip(&y)
            .zip(&z)
            .map(|((&x, &y), &z)| Vec3::new(x, y, z))
            .collect())
    };
    let [r, g, b, _] = channel::RGBA;
    // A photometric frame's colour is in cd/m² in the file, in units of its white in memory.
    let white_cd_m2 = match image
        .layer_data
        .attributes
        .other
        .get(&Text::from(WHITE_ATTRIBUTE))
    {
        None => None,
        Some(exr::meta::attribute::AttributeValue::F32(w)) if w.is_finite() && *w > 0.0 => Some(*w),
        Some(other) => bail!("attribute `{WHITE_ATTRIBUTE}` is {other:?}, expected a positive f32"),
    };
    let mut color = vec3s([r, g, b])?;
    if let Some(white) = white_cd_m2 {
        color.iter_mut().for_each(|c| *c /= white);
    }
    let frame = Frame {
        width,
        height,
        color,
        white_cd_m2,
        exposure: None,
        depth: f32s(channel::Z)?,
        camera_z: f32s(channel::CAMERA_Z)?,
        position: vec3s(channel::P)?,
        normal: vec3s(channel::N)?,
        object_id: u32s(channel::OBJECT_ID)?,
        part_id: u32s(channel::PART_ID)?,
    };
    check_samples(&frame)?;
    Ok(frame)
}

/// An error at the first sample seethru never writes, naming the channel, the pixel and what
/// is admissible: colours are finite; `Z` and `camera_z` are distances in [0, inf] m (inf for
/// the sky); `P` is a point of the world, each coordinate in [-1e6, 1e6] m, wherever `Z` is
/// finite (the sky's `P` is NaN); `N` is a unit vector (zero for the sky).
fn check_samples(frame: &Frame) -> Result<()> {
    let world = MAX_COORDINATE as f32;
    let at = |i: usize| (i % frame.width as usize, i / frame.width as usize);
    let refuse = |name: &str, i: usize, value: f32, admissible: &str| -> Result<()> {
        let (x, y) = at(i);
        bail!(
            "channel `{name}` at pixel ({x}, {y}) is {}: seethru writes {admissible}",
            short(value as f64)
        )
    };
    let [r, g, b, _] = channel::RGBA;
    for i in 0..frame.color.len() {
        let color = frame.color[i];
        for (name, value) in [r, g, b].into_iter().zip(color.to_array()) {
            if !value.is_finite() {
                refuse(name, i, value, "a finite linear colour")?;
            }
        }
        let depth = frame.depth[i];
        for (name, value) in [(channel::Z, depth), (channel::CAMERA_Z, frame.camera_z[i])] {
            if value.is_nan() || value < 0.0 {
                refuse(name, i, value, "a distance in [0, inf] m (inf for the sky)")?;
            }
        }
        if depth.is_finite() {
            for (name, value) in channel::P.into_iter().zip(frame.position[i].to_array()) {
                if value.is_nan() || value.abs() > world {
                    refuse(
                        name,
                        i,
                        value,
                        "a world coordinate in [-1e6, 1e6] m where `Z` is finite (NaN only for the sky)",
                    )?;
                }
            }
        }
        for (name, value) in channel::N.into_iter().zip(frame.normal[i].to_array()) {
            if value.is_nan() || value.abs() > 1.001 {
                refuse(name, i, value, "a unit vector, each component in [-1, 1]")?;
            }
        }
    }
    Ok(())
}

fn sample_type(samples: &FlatSamples) -> &'static str {
    match samples {
        FlatSamples::F16(_) => "f16",
        FlatSamples::F32(_) => "f32",
        FlatSamples::U32(_) => "u32",
    }
}

/// Writes `<name>.png`, `<name>_ids.png` and `<name>.exr` (holding `exr`) into `dir`.
pub fn write_frame(frame: &Frame, dir: &Path, name: &str, exr: ExrContent) -> Result<()> {
    write_frame_like(frame, dir, name, exr, None)
}

/// [`write_frame`] of a frame whole or rendered over another, the EXR's blocks reused from
/// `like` where they are the same ([`write_view_exr_like`]). The three files are encoded
/// side by side.
pub fn write_frame_like<'a>(
    frame: impl Into<FrameView<'a>>,
    dir: &Path,
    name: &str,
    exr: ExrContent,
    like: Option<&exr_zip::Zipped>,
) -> Result<()> {
    let frame = frame.into();
    write_frame_files(frame, dir, name, || {
        write_view_exr_like(frame, &dir.join(format!("{name}.exr")), exr, like)
    })
}

/// [`write_frame`], returning the EXR's blocks for the next file ([`write_frame_like`]).
pub fn write_frame_keeping<'a>(
    frame: &'a Frame,
    dir: &Path,
    name: &str,
    exr: ExrContent,
) -> Result<Option<exr_zip::Zipped<'a>>> {
    let mut zipped = None;
    write_frame_files(frame.into(), dir, name, || {
        zipped = write_view_exr_keeping(frame, &dir.join(format!("{name}.exr")), exr)?;
        Ok(())
    })?;
    Ok(zipped)
}

/// `<name>.png` and `<name>_ids.png` of `frame` into `dir`, beside `exr` (its EXR).
fn write_frame_files(
    frame: FrameView,
    dir: &Path,
    name: &str,
    exr: impl FnOnce() -> Result<()> + Send,
) -> Result<()> {
    let (pngs, exr) = rayon::join(
        || -> Result<()> {
            let (colour, ids) = rayon::join(
                || write_color_png(frame, &dir.join(format!("{name}.png"))),
                || write_id_png(frame, &dir.join(format!("{name}_ids.png"))),
            );
            colour.and(ids)
        },
        exr,
    );
    pngs.and(exr)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::frame::Pixel;

    #[test]
    fn an_id_png_darkens_each_part_by_an_eighth_over_four_parts() {
        let pixel = |object_id, part_id| Pixel {
            object_id,
            part_id,
            ..Pixel::SKY
        };
        let parts = [0, 1, 2, 3, 4, 7];
        let mut pixels: Vec<Pixel> = parts.iter().map(|&p| pixel(5, p)).collect();
        pixels.push(pixel(0, 2));
        let frame = Frame::from_pixels(pixels.len() as u32, 1, &pixels);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ids.png");
        write_id_png(&frame, &path).unwrap();
        let png = image::open(&path).unwrap().to_rgb8();
        let colour = id_color(5);
        let darkened = |eighths: u32| colour.map(|c| (u32::from(c) * eighths / 8) as u8);
        let expected = [8, 7, 6, 5, 8, 5].map(darkened);
        for (x, want) in expected.iter().enumerate() {
            assert_eq!(png.get_pixel(x as u32, 0).0, *want, "part {}", parts[x]);
        }
        assert_eq!(png.get_pixel(6, 0).0, [0, 0, 0], "sky, whatever its part");
    }
}
