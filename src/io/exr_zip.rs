//! OpenEXR's ZIP compression (16 scan lines a block), with a faster deflate than the exr
//! crate's and the blocks compressed on rayon's threads.
//!
//! The file is a standard ZIP-compressed EXR: each block's samples are laid out little-endian
//! line by line and channel by channel, split into even and odd bytes, delta-coded (+128) and
//! deflated into a zlib stream, exactly as OpenEXR's `ImfZip` and the exr crate do; a block
//! that would not shrink is stored raw, as the format requires. Only the deflate differs: the
//! exr crate runs miniz_oxide at level 4; seethru runs level 1 (greedy matching), which took
//! a quarter of the CPU for 6 % more bytes on das's views (docs/guide/performance.md). Every
//! zlib reader inflates it: the exr crate, OpenEXR (OpenCV, imageio, Blender, Nuke).
//!
//! The bytes do not depend on the thread count: each block is compressed on its own and the
//! blocks are written in order. On a big-endian machine the exr crate's own ZIP writer is used
//! (the layout above is little-endian); the tests compare the two (`tests/exr.rs`).

use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
use exr::block::writer::ChunksWriter;
use exr::block::{BlockIndex, UncompressedBlock};
use exr::image::write::layers::{LayersWriter, WritableLayers};
use exr::meta::header::Header;
use exr::prelude::*;
use glam::Vec3;
use rayon::prelude::*;

/// The compression written in the header: ZIP over blocks of 16 scan lines.
pub const COMPRESSION: Compression = Compression::ZIP16;

/// miniz_oxide's level: 1, the fastest that still finds matches (level 4 is the exr crate's).
pub const DEFLATE_LEVEL: u8 = 1;

/// Writes `image` (one layer of flat samples, scan lines, [`COMPRESSION`]) as an EXR to a
/// buffered `write`.
pub fn write(
    image: &Image<Layer<AnyChannels<FlatSamples>>>,
    write: impl std::io::Write + std::io::Seek,
) -> exr::error::Result<()> {
    if cfg!(target_endian = "big") || image.layer_data.encoding.compression != COMPRESSION {
        return image.write().to_buffered(write);
    }
    let headers = image.layer_data.infer_headers(&image.attributes);
    let layers = image.layer_data.create_writer(&headers);
    write_blocks(write, headers, |meta, index| {
        layers.extract_uncompressed_block(meta, index)
    })
}

/// Writes the file's blocks in order, each one's samples from `samples` (little-endian, line
/// by line, channel by channel) zipped on rayon's threads.
fn write_blocks(
    write: impl std::io::Write + std::io::Seek,
    headers: exr::meta::Headers,
    samples: impl Fn(&[Header], BlockIndex) -> Vec<u8> + Sync,
) -> exr::error::Result<()> {
    exr::block::write(write, headers, true, |meta, chunk_writer| {
        let blocks: Vec<_> = meta.enumerate_ordered_header_block_indices().collect();
        // A few blocks per thread at a time: the compressed chunks wait for their turn in
        // memory, not the whole image's.
        let group = 4 * rayon::current_num_threads();
        for blocks in blocks.chunks(group) {
            let chunks: Vec<(usize, Chunk)> = blocks
                .par_iter()
                .map(|&(at, index)| {
                    let data = samples(&meta.headers, index);
                    (
                        at,
                        zip_chunk(UncompressedBlock { index, data }, &meta.headers),
                    )
                })
                .collect();
            for (at, chunk) in chunks {
                chunk_writer.write_chunk(at, chunk)?;
            }
        }
        Ok(())
    })
}

/// One channel's samples, borrowed from where they live (a frame's buffers): what
/// [`write_planes`] reads block by block instead of copying whole channels first.
#[derive(Clone, Copy, Debug)]
pub enum Plane<'a> {
    /// f32 samples, one per pixel, row-major.
    F32(&'a [f32]),
    /// u32 samples, one per pixel, row-major.
    U32(&'a [u32]),
    /// Component 0, 1 or 2 (x, y, z) of vectors, one per pixel, row-major; written as f32.
    Component(&'a [Vec3], usize),
    /// The same f32 at every pixel.
    Constant(f32),
}

impl Plane<'_> {
    fn sample_type(&self) -> FlatSamples {
        match self {
            Plane::U32(_) => FlatSamples::U32(Vec::new()),
            _ => FlatSamples::F32(Vec::new()),
        }
    }

    /// Appends the samples of pixels `from..from + count` as little-endian bytes.
    fn append_le(&self, from: usize, count: usize, out: &mut Vec<u8>) {
        let range = from..from + count;
        match *self {
            Plane::F32(v) => out.extend(v[range].iter().flat_map(|s| s.to_le_bytes())),
            Plane::U32(v) => out.extend(v[range].iter().flat_map(|s| s.to_le_bytes())),
            Plane::Component(v, axis) => {
                out.extend(v[range].iter().flat_map(|s| s[axis].to_le_bytes()))
            }
            Plane::Constant(c) => {
                let bytes = c.to_le_bytes();
                out.extend((0..count).flat_map(|_| bytes))
            }
        }
    }

    fn len(&self) -> Option<usize> {
        match self {
            Plane::F32(v) => Some(v.len()),
            Plane::U32(v) => Some(v.len()),
            Plane::Component(v, _) => Some(v.len()),
            Plane::Constant(_) => None,
        }
    }
}

/// Writes named channels of a `width`×`height` image as one single-part, unnamed-layer EXR
/// with [`COMPRESSION`], reading each block's samples straight from `planes`: the same bytes
/// as [`write`] given the channels as owned samples (its twin in the tests), without a copy of
/// every channel. The samples are written little-endian on any machine.
pub fn write_planes(
    width: usize,
    height: usize,
    planes: &[(&str, Plane<'_>)],
    write: impl std::io::Write + std::io::Seek,
) -> exr::error::Result<()> {
    let pixels = width * height;
    if let Some((name, plane)) = planes
        .iter()
        .find(|(_, p)| p.len().is_some_and(|n| n != pixels))
    {
        return Err(exr::error::Error::Invalid(
            format!(
                "channel {name} has {} samples for {width}×{height} pixels",
                plane.len().unwrap_or(0)
            )
            .into(),
        ));
    }
    // The header as the exr crate infers it, from channels without samples.
    let channels = planes
        .iter()
        .map(|(name, plane)| AnyChannel::new(*name, plane.sample_type()))
        .collect();
    let layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        Encoding {
            compression: COMPRESSION,
            ..Encoding::UNCOMPRESSED
        },
        AnyChannels::sort(channels),
    );
    let image = Image::from_layer(layer);
    // The planes in the file's channel order (sorted by name).
    let sorted: Vec<Plane> = image
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| {
            planes
                .iter()
                .find(|(name, _)| c.name.eq(name))
                .map(|(_, p)| *p)
                .expect("every sorted channel is one of the planes")
        })
        .collect();
    let names = &image.layer_data.channel_data.list;
    if names.windows(2).any(|pair| pair[0].name == pair[1].name) {
        return Err(exr::error::Error::Invalid("duplicate channel name".into()));
    }
    let headers = image.layer_data.infer_headers(&image.attributes);
    write_blocks(write, headers, |_, index| {
        let (x0, y0) = (index.pixel_position.x(), index.pixel_position.y());
        let (w, h) = (index.pixel_size.width(), index.pixel_size.height());
        let mut data = Vec::with_capacity(w * h * 4 * sorted.len());
        for y in y0..y0 + h {
            for plane in &sorted {
                plane.append_le(y * width + x0, w, &mut data);
            }
        }
        data
    })
}

/// One scan-line block as a ZIP chunk (raw when deflating does not shrink it).
fn zip_chunk(block: UncompressedBlock, headers: &[Header]) -> Chunk {
    let header = &headers[block.index.layer];
    // Within i32: the exr crate checked the layer's bounds when it inferred the header.
    let y_coordinate =
        block.index.pixel_position.y() as i32 + header.own_attributes.layer_position.y();
    // Little-endian already (the caller checked): the samples as the file stores them.
    let raw = block.data;
    let packed = predicted(&raw);
    let deflated = miniz_oxide::deflate::compress_to_vec_zlib(&packed, DEFLATE_LEVEL);
    let compressed_pixels_le = if deflated.len() < raw.len() {
        deflated
    } else {
        raw
    };
    Chunk {
        layer_index: block.index.layer,
        compressed_block: CompressedBlock::ScanLine(CompressedScanLineBlock {
            y_coordinate,
            compressed_pixels_le,
        }),
    }
}

/// OpenEXR's ZIP predictor: the even bytes then the odd ones, each byte replaced by its
/// difference from the one before it there, plus 128 (wrapping); the first byte as it is.
/// One pass over strided bytes (the obvious split-then-difference is the tests' twin).
pub fn predicted(raw: &[u8]) -> Vec<u8> {
    let Some(&first) = raw.first() else {
        return Vec::new();
    };
    let delta = |(&b, &a): (&u8, &u8)| b.wrapping_sub(a).wrapping_add(128);
    let mut out = Vec::with_capacity(raw.len());
    out.push(first);
    let from = |at: usize| raw.get(at..).unwrap_or_default().iter().step_by(2);
    out.extend(from(2).zip(from(0)).map(delta));
    if raw.len() > 1 {
        let last_even = (raw.len() - 1) & !1;
        out.push(raw[1].wrapping_sub(raw[last_even]).wrapping_add(128));
        out.extend(from(3).zip(from(1)).map(delta));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The predictor as OpenEXR's ImfZip.cpp writes it: split, then difference in place.
    fn split_then_differenced(raw: &[u8]) -> Vec<u8> {
        let half = raw.len().div_ceil(2);
        let mut out = vec![0u8; raw.len()];
        for (i, &b) in raw.iter().enumerate() {
            out[if i % 2 == 0 { i / 2 } else { half + i / 2 }] = b;
        }
        for i in (1..out.len()).rev() {
            out[i] = out[i].wrapping_sub(out[i - 1]).wrapping_add(128);
        }
        out
    }

    #[test]
    fn the_predictor_splits_then_differences() {
        // 10 20 30 40 50 → even 10 30 50, odd 20 40 → 10, 30-10+128, 50-30+128, 20-50+128,
        // 40-20+128.
        assert_eq!(predicted(&[10, 20, 30, 40, 50]), [10, 148, 148, 98, 148]);
        let bytes: Vec<u8> = (0..1000u32)
            .map(|i| (crate::util::sampling::hash_u32(i) >> 7) as u8)
            .collect();
        for n in 0..40 {
            assert_eq!(
                predicted(&bytes[..n]),
                split_then_differenced(&bytes[..n]),
                "{n}"
            );
        }
        assert_eq!(predicted(&bytes), split_then_differenced(&bytes));
    }
}
