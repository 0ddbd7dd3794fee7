//! Display maps and display images that an outside method writes (`seethru score --map`,
//! `--display-image`, `compare --methods map:NAME=FILE`): read and checked here, turned into
//! the system's `DisplayMap`/`DisplayImage` by the command.
//!
//! A map is (display height, display width, 2): `[..., 0]` = x and `[..., 1]` = y, frontal
//! pixels in OpenCV's `remap` convention. `.npy`: float32 or float64, little- or big-endian,
//! C or Fortran order (NumPy's format 1.0–3.0). `.exr`: channels `x` and `y` (f16/f32), with
//! an optional string attribute `capture_fingerprint`. A sidecar `<map>.json` holding
//! `{"capture_fingerprint": "…"}` states the capture it was made for, in either format.

use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::*;

use crate::util::message::printable;

/// A map as read: width, height, and row-major (x, y) per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct MapFile {
    pub width: u32,
    pub height: u32,
    pub xy: Vec<[f32; 2]>,
    /// From the EXR's `capture_fingerprint` attribute or the `<map>.json` sidecar.
    pub fingerprint: Option<String>,
}

/// The EXR attribute naming the capture a map was made for.
const FINGERPRINT_ATTRIBUTE: &str = "capture_fingerprint";

/// Most pixels of a map (the display's resolution is far smaller).
const MAX_MAP_PIXELS: u64 = 1 << 26;

/// Reads a map by its extension (`.npy` or `.exr`); errors name the file.
pub fn read_map(path: &Path) -> Result<MapFile> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let shown = path.display();
    let mut map = match ext.as_deref() {
        Some("npy") => {
            let bytes = read_bytes(path)?;
            parse_npy(&bytes).with_context(|| format!("{shown}: not a display map"))?
        }
        Some("exr") => read_exr_map(path).with_context(|| format!("{shown}: not a display map"))?,
        _ => bail!("{shown}: a display map must be .npy or .exr (channels x, y)"),
    };
    if map.fingerprint.is_none() {
        map.fingerprint = sidecar_fingerprint(path)?;
    }
    Ok(map)
}

fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    if let Some(why) = crate::util::input_file::not_a_file(path) {
        bail!("cannot read {}: {why}", path.display());
    }
    std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))
}

/// `<map>.json`'s `capture_fingerprint`, when the file exists.
fn sidecar_fingerprint(path: &Path) -> Result<Option<String>> {
    let mut name = path.as_os_str().to_owned();
    name.push(".json");
    let sidecar = std::path::PathBuf::from(name);
    if !sidecar.exists() {
        return Ok(None);
    }
    let text = String::from_utf8(read_bytes(&sidecar)?)
        .with_context(|| format!("{}: not UTF-8 text", sidecar.display()))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", sidecar.display()))?;
    match value.get("capture_fingerprint") {
        Some(serde_json::Value::String(s)) => fingerprint_text(s)
            .map(Some)
            .with_context(|| sidecar.display().to_string()),
        Some(other) => bail!(
            "{}: capture_fingerprint must be a string of 16 hex digits, got {other}",
            sidecar.display()
        ),
        None => bail!(
            "{}: no key capture_fingerprint (the sidecar states the capture the map was made for)",
            sidecar.display()
        ),
    }
}

/// A stated capture fingerprint, refused unless it is one (16 hex digits, as
/// `capture::fingerprint` writes them): it is echoed in the messages of a mismatch.
pub fn fingerprint_text(text: &str) -> Result<String> {
    if text.len() == 16 && text.bytes().all(|b| b.is_ascii_hexdigit()) {
        Ok(text.to_string())
    } else {
        let shown: String = text.chars().take(40).collect();
        let more = if shown.len() < text.len() { "…" } else { "" };
        bail!("capture_fingerprint must be a string of 16 hex digits, got {shown:?}{more}")
    }
}

/// A `.npy` file's bytes as a map.
pub fn parse_npy(bytes: &[u8]) -> Result<MapFile> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        bail!("not a .npy file (no \\x93NUMPY magic)");
    }
    let major = bytes[6];
    let (len, start) = match major {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        _ => bail!(".npy format version {major} is not 1, 2 or 3"),
    };
    let header = bytes
        .get(start..start + len)
        .context("the .npy header is truncated")?;
    let header = std::str::from_utf8(header).context("the .npy header is not text")?;
    let descr = dict_value(header, "descr").context("the .npy header has no 'descr'")?;
    let descr = descr.trim_matches(|c| c == '\'' || c == '"');
    let fortran = match dict_value(header, "fortran_order").as_deref() {
        Some("True") => true,
        Some("False") => false,
        _ => bail!("the .npy header has no fortran_order True/False"),
    };
    let shape_text = dict_value(header, "shape").context("the .npy header has no 'shape'")?;
    // The header's text is echoed in messages: its line breaks and escapes shown, not obeyed.
    let (shape_shown, descr_shown) = (printable(&shape_text), printable(descr));
    let shape: Vec<u64> = shape_text
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<u64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("the .npy shape {shape_shown} is not a tuple of integers"))?;
    let (elem, big) = match descr {
        "<f4" | "=f4" => (4, false),
        ">f4" => (4, true),
        "<f8" | "=f8" => (8, false),
        ">f8" => (8, true),
        _ => bail!(
            "the map's dtype is {descr_shown}: float32 or float64 expected (numpy: map.astype(np.float32))"
        ),
    };
    let [h, w, c] = shape[..] else {
        bail!(
            "the map has shape {shape_shown}: (display height, display width, 2) expected, with [..., 0] = x and [..., 1] = y"
        );
    };
    if c != 2 {
        bail!(
            "the map has {c} channels (shape {shape_shown}): 2 expected, [..., 0] = x and [..., 1] = y"
        );
    }
    if w == 0 || h == 0 || w.saturating_mul(h) > MAX_MAP_PIXELS {
        bail!("the map is {w}×{h} pixels: each side ≥ 1, at most {MAX_MAP_PIXELS} pixels");
    }
    let data = &bytes[start + len..];
    let count = (w * h * 2) as usize;
    if data.len() != count * elem {
        bail!(
            "the .npy data holds {} bytes, its shape {shape_shown} of {descr_shown} needs {}",
            data.len(),
            count * elem
        );
    }
    let value = |k: usize| -> f32 {
        let b = &data[k * elem..(k + 1) * elem];
        match (elem, big) {
            (4, false) => f32::from_le_bytes(b.try_into().unwrap_or([0; 4])),
            (4, true) => f32::from_be_bytes(b.try_into().unwrap_or([0; 4])),
            (_, false) => f64::from_le_bytes(b.try_into().unwrap_or([0; 8])) as f32,
            (_, true) => f64::from_be_bytes(b.try_into().unwrap_or([0; 8])) as f32,
        }
    };
    let (w, h) = (w as usize, h as usize);
    let xy = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            // C order: (y, x, c) at (y W + x) 2 + c; Fortran: at y + H (x + W c).
            let at = |c: usize| match fortran {
                false => i * 2 + c,
                true => y + h * (x + w * c),
            };
            [value(at(0)), value(at(1))]
        })
        .collect();
    Ok(MapFile {
        width: w as u32,
        height: h as u32,
        xy,
        fingerprint: None,
    })
}

/// The text of `key`'s value in a Python dict literal such as a .npy header.
fn dict_value(header: &str, key: &str) -> Option<String> {
    let at = header
        .find(&format!("'{key}'"))
        .or_else(|| header.find(&format!("\"{key}\"")))?;
    let rest = &header[at + key.len() + 2..];
    let rest = rest.trim_start().strip_prefix(':')?.trim_start();
    let end = if rest.starts_with('(') {
        rest.find(')')? + 1
    } else {
        rest.find([',', '}'])?
    };
    Some(rest[..end].trim().to_string())
}

fn read_exr_map(path: &Path) -> Result<MapFile> {
    if let Some(why) = crate::util::input_file::not_a_file(path) {
        bail!("cannot read {}: {why}", path.display());
    }
    let open = || -> Result<std::io::BufReader<std::fs::File>> {
        let file =
            std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
        Ok(std::io::BufReader::new(file))
    };
    exr_map_from(open)
}

/// An EXR map's bytes as a map (the fuzz target's entry; `read_map` reads the file).
pub fn parse_exr_map(bytes: &[u8]) -> Result<MapFile> {
    exr_map_from(|| Ok(std::io::Cursor::new(bytes)))
}

/// The map of the EXR that `open` reads from its start: once for the header (its size is
/// checked before anything is decoded), once for the channels.
fn exr_map_from<R: std::io::Read + std::io::Seek>(open: impl Fn() -> Result<R>) -> Result<MapFile> {
    let meta = exr::meta::MetaData::read_from_buffered(open()?, false)
        .map_err(|e| anyhow::anyhow!("not a readable EXR: {e}"))?;
    // Every layer's size, as the first one that reads may not be the first in the file.
    if meta.headers.is_empty() {
        bail!("the EXR has no layer");
    }
    for header in meta.headers.iter() {
        let size = header.layer_size;
        if (size.width() as u64) * (size.height() as u64) > MAX_MAP_PIXELS {
            bail!(
                "the map is {}×{} pixels: at most {MAX_MAP_PIXELS}",
                size.width(),
                size.height()
            );
        }
    }
    let reader = open()?;
    let image = crate::io::frame_files::read_first_layer(|r| r.from_buffered(reader))?;
    let layer = &image.layer_data;
    let names: Vec<String> = layer
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    let channel = |name: &str| -> Result<Vec<f32>> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .with_context(|| {
                format!(
                    "no channel `{name}`: a map EXR has channels x and y, this one has {names:?}"
                )
            })?;
        match &c.sample_data {
            FlatSamples::F32(v) => Ok(v.clone()),
            FlatSamples::F16(v) => Ok(v.iter().map(|h| h.to_f32()).collect()),
            FlatSamples::U32(_) => bail!("channel `{name}` is u32: f32 or f16 expected"),
        }
    };
    let (x, y) = (channel("x")?, channel("y")?);
    let fingerprint = image
        .attributes
        .other
        .iter()
        .chain(layer.attributes.other.iter())
        .find(|(k, _)| *k == FINGERPRINT_ATTRIBUTE)
        .map(|(_, v)| match v {
            exr::meta::attribute::AttributeValue::Text(t) => fingerprint_text(&t.to_string()),
            _ => bail!("the attribute capture_fingerprint must be a string of 16 hex digits"),
        })
        .transpose()?;
    let size = layer.size;
    if x.len() != size.area() || y.len() != size.area() {
        bail!(
            "the channels x and y hold {} and {} samples, the layer's {}×{} pixels need {}",
            x.len(),
            y.len(),
            size.width(),
            size.height(),
            size.area()
        );
    }
    Ok(MapFile {
        width: size.width() as u32,
        height: size.height() as u32,
        xy: x.into_iter().zip(y).map(|(x, y)| [x, y]).collect(),
        fingerprint,
    })
}

/// Writes a float32 array of `shape` (row-major, C order) as a NumPy 1.0 `.npy` file,
/// whole or not at all.
pub fn write_npy_f32(path: &Path, shape: &[usize], data: &[f32]) -> Result<()> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let tuple = if dims.len() == 1 {
        format!("({},)", dims[0])
    } else {
        format!("({})", dims.join(", "))
    };
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {tuple}, }}");
    // NumPy pads the header with spaces and a newline to a multiple of 64 bytes.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    for v in data {
        bytes.extend(v.to_le_bytes());
    }
    crate::io::atomic::write_atomically(path, |file| {
        use std::io::Write;
        file.write_all(&bytes)?;
        Ok(())
    })
}

/// A display image as read: width, height, linear RGB per pixel (row-major).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageFile {
    pub width: u32,
    pub height: u32,
    pub color: Vec<[f32; 3]>,
}

/// Reads a method's display image: an 8-bit sRGB PNG (decoded to linear) or an EXR with
/// linear `R`, `G`, `B` channels; or, with `codes`, the display's codes: a PNG's (8 or 16
/// bits) as code / top code, an EXR's as they are.
pub fn read_display_image(path: &Path, codes: bool) -> Result<ImageFile> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let shown = path.display();
    match ext.as_deref() {
        Some("png") => {
            let bytes = read_bytes(path)?;
            let image = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
                .with_context(|| format!("{shown}: not a readable PNG"))?;
            let color = if codes {
                (image.to_rgb16().pixels())
                    .map(|p| p.0.map(|c| f32::from(c) / 65535.0))
                    .collect()
            } else {
                (image.to_rgb8().pixels())
                    .map(|p| p.0.map(crate::util::color::decode_srgb8))
                    .collect()
            };
            Ok(ImageFile {
                width: image.width(),
                height: image.height(),
                color,
            })
        }
        Some("exr") => {
            if let Some(why) = crate::util::input_file::not_a_file(path) {
                bail!("cannot read {shown}: {why}");
            }
            let image = read_first_rgba_layer_from_file(
                path,
                |size, _| (size.width(), vec![[0f32; 3]; size.width() * size.height()]),
                |(w, pixels): &mut (usize, Vec<[f32; 3]>),
                 pos,
                 (r, g, b, _a): (f32, f32, f32, f32)| {
                    pixels[pos.y() * *w + pos.x()] = [r, g, b];
                },
            )
            .map_err(|e| anyhow::anyhow!("{shown}: not a readable RGB EXR: {e}"))?;
            let size = image.layer_data.size;
            Ok(ImageFile {
                width: size.width() as u32,
                height: size.height() as u32,
                color: image.layer_data.channel_data.pixels.1,
            })
        }
        _ => bail!("{shown}: a display image must be .png (sRGB) or .exr (linear R, G, B)"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn npy(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
        let mut header = format!(
            "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}",
            if fortran { "True" } else { "False" }
        );
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend((header.len() as u16).to_le_bytes());
        out.extend(header.as_bytes());
        out.extend(data);
        out
    }

    /// A 2 × 3 map whose entry at (row j, column i) is x = 10 i + 1, y = 10 j + 2, laid out
    /// by hand in both orders and both float widths: every layout reads to the same map.
    #[test]
    fn c_and_fortran_order_and_both_widths_read_alike() {
        let (h, w) = (2usize, 3usize);
        let value =
            |j: usize, i: usize, c: usize| (10 * (if c == 0 { i } else { j }) + 1 + c) as f64;
        let mut c32 = Vec::new();
        let mut f64s = Vec::new();
        for j in 0..h {
            for i in 0..w {
                for c in 0..2 {
                    c32.extend((value(j, i, c) as f32).to_le_bytes());
                }
            }
        }
        for c in 0..2 {
            for i in 0..w {
                for j in 0..h {
                    f64s.extend(value(j, i, c).to_le_bytes());
                }
            }
        }
        let a = parse_npy(&npy("<f4", false, "(2, 3, 2)", &c32)).unwrap();
        let b = parse_npy(&npy("<f8", true, "(2, 3, 2)", &f64s)).unwrap();
        assert_eq!(a, b);
        assert_eq!((a.width, a.height), (3, 2));
        // Row 1, column 2: x = 21, y = 12.
        assert_eq!(a.xy[w + 2], [21.0, 12.0]);
    }

    #[test]
    fn bad_maps_say_what_is_wrong() {
        let err = |b: Vec<u8>| format!("{:#}", parse_npy(&b).unwrap_err());
        assert!(err(npy("<i4", false, "(2, 3, 2)", &[0; 48])).contains("float32 or float64"));
        assert!(err(npy("<f4", false, "(2, 3, 3)", &[0; 72])).contains("3 channels"));
        assert!(err(npy("<f4", false, "(6, 2)", &[0; 48])).contains("(display height"));
        assert!(err(npy("<f4", false, "(2, 3, 2)", &[0; 40])).contains("needs 48"));
        assert!(err(b"PK\x03\x04 not numpy".to_vec()).contains("magic"));
    }
}
