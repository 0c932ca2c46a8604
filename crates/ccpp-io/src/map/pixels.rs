//! Image decoding and conversion of pixels to cells.
//!
//! Grey level rule (documented in [`crate::map`]): grey images use their value; colour images
//! use the exact mean `(R + G + B) / 3` as an `f64` (no rounding, as `map_server` does); alpha
//! is ignored except in `scale` mode, where a transparent pixel is unknown; 16-bit samples are mapped to the 0..=255 scale as `v / 257` (exact, not truncated
//! to 8 bits first); float samples as `v * 255` clamped to `[0, 255]`.

use std::io::{BufRead, Seek, SeekFrom};
use std::path::Path;

use ccpp_core::grid::Cell;
use image::{DynamicImage, ImageReader};

use super::classify::{MapMode, Thresholds};
use super::error::{one_line, MapError};

/// Width, height and row-major cells (row 0 on top) of a decoded and classified image.
pub(crate) struct Classified {
    pub width: usize,
    pub height: usize,
    pub cells: Vec<Cell>,
}

/// Bytes a decoded pixel takes at most (16-bit RGBA).
const DECODED_BYTES_MAX: u64 = 8;
/// Decoder allocations beside the decoded image (row buffers, the compressed stream's window).
const DECODER_ROOM: u64 = 64 << 20;

/// The decoder's limits for an image of at most `max_pixels` pixels: its allocation cap at
/// least the decoded buffer of that many pixels at the widest sample plus working room, and
/// never below the decoder's default.
fn decoder_limits(max_pixels: u64) -> image::Limits {
    let mut limits = image::Limits::default();
    let need = max_pixels
        .saturating_mul(DECODED_BYTES_MAX)
        .saturating_add(DECODER_ROOM);
    limits.max_alloc = Some(limits.max_alloc.unwrap_or(0).max(need));
    limits
}

/// Decodes an image (format guessed from its content) and classifies every pixel. The decoded
/// image buffer is dropped before returning, so at most the image plus the cells are alive.
/// With `max_pixels`, the image's size is read from its header first and a larger image is
/// refused before anything of its size is allocated.
pub(crate) fn decode_and_classify<R: BufRead + Seek>(
    reader: ImageReader<R>,
    path: &Path,
    t: &Thresholds,
    max_pixels: Option<u64>,
) -> Result<Classified, MapError> {
    let decode_err = |e: &dyn std::fmt::Display| MapError::Decode {
        path: path.to_path_buf(),
        message: one_line(&e.to_string()),
    };
    let io_err = |e: std::io::Error| MapError::Io {
        path: path.to_path_buf(),
        source: e,
    };
    let reader = reader.with_guessed_format().map_err(io_err)?;
    let Some(format) = reader.format() else {
        return Err(MapError::Decode {
            path: path.to_path_buf(),
            message: "not a PNG or PNM/PGM image (unrecognised content)".to_owned(),
        });
    };
    let image_err = |e: image::ImageError| match e {
        image::ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            MapError::Decode {
                path: path.to_path_buf(),
                message: "truncated: the file ends before its image data does".to_owned(),
            }
        }
        other => decode_err(&other),
    };
    let reader = match max_pixels {
        None => reader,
        Some(max) => {
            // The header alone, by a second reader over the same stream, which then goes back
            // to where the image starts.
            let mut inner = reader.into_inner();
            let start = inner.stream_position().map_err(io_err)?;
            let (width, height) = ImageReader::with_format(&mut inner, format)
                .into_dimensions()
                .map_err(image_err)?;
            if u64::from(width) * u64::from(height) > max {
                return Err(MapError::TooLarge {
                    path: path.to_path_buf(),
                    width,
                    height,
                    max_pixels: max,
                });
            }
            inner.seek(SeekFrom::Start(start)).map_err(io_err)?;
            let mut r = ImageReader::with_format(inner, format);
            // The decoder's own allocation cap (512 MiB by default) must not refuse an image
            // the caller's budget admits (`--max-memory 60000` still failed on a 24000 x 24000
            // PNG with "Memory limit exceeded"): it is raised to the decoded buffer of
            // `max` pixels at the widest sample (16-bit RGBA, 8 bytes), plus working room.
            r.limits(decoder_limits(max));
            r
        }
    };
    let img = reader.decode().map_err(image_err)?;
    let width = img.width() as usize;
    let height = img.height() as usize;
    let cells = classify_image(&img, t);
    drop(img);
    Ok(Classified {
        width,
        height,
        cells,
    })
}

/// Classifies every pixel of a decoded image, row-major from the top row.
fn classify_image(img: &DynamicImage, t: &Thresholds) -> Vec<Cell> {
    let n = img.width() as usize * img.height() as usize;
    let mut cells = Vec::with_capacity(n);
    // Scale mode: a pixel whose alpha is below its maximum is unknown.
    let alpha = t.mode == MapMode::Scale;
    let seen = |opaque: bool, c: Cell| if opaque || !alpha { c } else { Cell::Unknown };
    match img {
        DynamicImage::ImageLuma8(b) => {
            let lut = t.lut();
            cells.extend(b.as_raw().iter().map(|&v| lut[usize::from(v)]));
        }
        DynamicImage::ImageLumaA8(b) => {
            let lut = t.lut();
            cells.extend(
                b.as_raw()
                    .chunks_exact(2)
                    .map(|p| seen(p[1] == u8::MAX, lut[usize::from(p[0])])),
            );
        }
        DynamicImage::ImageRgb8(b) => {
            let lut = sum_lut(t);
            cells.extend(b.as_raw().chunks_exact(3).map(|p| lut[rgb_sum(p)]));
        }
        DynamicImage::ImageRgba8(b) => {
            let lut = sum_lut(t);
            cells.extend(
                b.as_raw()
                    .chunks_exact(4)
                    .map(|p| seen(p[3] == u8::MAX, lut[rgb_sum(p)])),
            );
        }
        DynamicImage::ImageLuma16(b) => {
            cells.extend(
                b.as_raw()
                    .iter()
                    .map(|&v| t.classify_level(level16(f64::from(v)))),
            );
        }
        DynamicImage::ImageLumaA16(b) => {
            cells.extend(
                b.as_raw()
                    .chunks_exact(2)
                    .map(|p| seen(p[1] == u16::MAX, t.classify_level(level16(f64::from(p[0]))))),
            );
        }
        DynamicImage::ImageRgb16(b) => {
            cells.extend(
                b.as_raw()
                    .chunks_exact(3)
                    .map(|p| t.classify_level(rgb16_level(p))),
            );
        }
        DynamicImage::ImageRgba16(b) => {
            cells.extend(
                b.as_raw()
                    .chunks_exact(4)
                    .map(|p| seen(p[3] == u16::MAX, t.classify_level(rgb16_level(p)))),
            );
        }
        other => {
            // Float images (and any future variant): go through 32-bit float RGBA.
            let rgba = other.to_rgba32f();
            cells.extend(rgba.as_raw().chunks_exact(4).map(|p| {
                let mean = (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0;
                seen(
                    p[3] >= 1.0,
                    t.classify_level((mean * 255.0).clamp(0.0, 255.0)),
                )
            }));
        }
    }
    debug_assert_eq!(cells.len(), n);
    cells
}

/// `R + G + B` of an 8-bit pixel (alpha, if any, is ignored).
#[inline]
fn rgb_sum(p: &[u8]) -> usize {
    usize::from(p[0]) + usize::from(p[1]) + usize::from(p[2])
}

/// Classification of every possible 8-bit `R + G + B` sum (0..=765), using the exact mean.
fn sum_lut(t: &Thresholds) -> Vec<Cell> {
    (0..=765u16)
        .map(|s| t.classify_level(f64::from(s) / 3.0))
        .collect()
}

/// A 16-bit sample on the 0..=255 scale.
#[inline]
fn level16(v: f64) -> f64 {
    v / 257.0
}

/// Mean of R, G, B of a 16-bit pixel on the 0..=255 scale.
#[inline]
fn rgb16_level(p: &[u16]) -> f64 {
    (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / (3.0 * 257.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decoder's default cap (512 MiB) refused a 24000 x 24000 PNG under
    /// `--max-memory 60000` ("Memory limit exceeded"): the cap follows the pixel budget.
    #[test]
    fn the_decoder_cap_follows_the_pixel_budget() {
        let default = image::Limits::default().max_alloc.unwrap();
        // A small budget keeps the decoder's default.
        assert_eq!(decoder_limits(1000).max_alloc, Some(default));
        // 24000 x 24000 grey pixels (576 MB decoded, over the default) fit.
        let px = 24_000u64 * 24_000;
        let cap = decoder_limits(px).max_alloc.unwrap();
        assert!(cap >= px * DECODED_BYTES_MAX && cap > default, "{cap}");
        assert_eq!(decoder_limits(u64::MAX).max_alloc, Some(u64::MAX));
    }
}
