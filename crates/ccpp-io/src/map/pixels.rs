//! Image decoding and conversion of pixels to cells.
//!
//! Grey level rule (documented in [`crate::map`]): grey images use their value; colour images
//! use the exact mean `(R + G + B) / 3` as an `f64` (no rounding, as `map_server` does); alpha
//! is ignored except in `scale` mode, where a transparent pixel is unknown; 16-bit samples are mapped to the 0..=255 scale as `v / 257` (exact, not truncated
//! to 8 bits first); float samples as `v * 255` clamped to `[0, 255]`.

use std::io::{BufRead, Read as _, Seek, SeekFrom};
use std::path::Path;

use ccpp_core::grid::Cell;
use image::{DynamicImage, ImageDecoder as _, ImageReader};

use super::classify::{MapMode, Thresholds};
use super::error::{one_line, MapError};

/// Width, height and row-major cells (row 0 on top) of a decoded and classified image.
pub(crate) struct Classified {
    pub width: usize,
    pub height: usize,
    pub cells: Vec<Cell>,
    /// Pixels ROS `map_server` classifies otherwise ([`alpha_averaged_differs`]).
    pub alpha_differs: usize,
}

/// Bytes a decoded pixel takes at most (16-bit RGBA).
const DECODED_BYTES_MAX: u64 = 8;
/// Decoder allocations beside the decoded image: row buffers, the compressed stream's window,
/// the palette and whatever ancillary chunks it inflates. A PNG's colour profile (`iCCP`) is
/// inflated whole: a 0.5 MB file whose profile inflates to 500 MiB peaked at 531 MB under
/// `--max-memory 17` while the decoder's cap was at least its 512 MiB default. Real profiles
/// are a few kilobytes to a few hundred; one beyond the room is skipped by the decoder (the
/// profile means nothing to an occupancy grid). Row buffers take a few rows of the widest
/// image (24000 px of 16-bit RGBA: 192 KB a row).
const DECODER_ROOM: u64 = 4 << 20;

/// Most bytes an image file takes per pixel: a plain (`P3`) PNM of 16-bit RGB samples writes
/// up to 18 characters a pixel, with room for extra whitespace; binary formats take at most 8.
const FILE_BYTES_PER_PIXEL: u64 = 24;

/// Room an image file may have beyond its pixels' bytes ([`FILE_BYTES_PER_PIXEL`]) for
/// metadata and comments (a 6 MB `tEXt` chunk in a 200 x 200 px map loads).
const METADATA_ROOM: u64 = 16 << 20;

/// The decoder's limits for an image of `pixels` pixels in a file of `file_bytes` bytes: its
/// allocation cap is the decoded buffer of that many pixels at the widest sample, plus
/// [`DECODER_ROOM`], plus three times the file's size (a chunk the decoder keeps as it is, such
/// as text or EXIF metadata, is no larger than the file, and is held while its buffer doubles
/// and once more as text: a 6 MB `tEXt` in a 200 x 200 map must load; only what the decoder
/// inflates, a colour profile, can outgrow it). 0 pixels: the header and
/// the chunks before the image data.
fn decoder_limits(pixels: u64, file_bytes: u64) -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(
        pixels
            .saturating_mul(DECODED_BYTES_MAX)
            .saturating_add(DECODER_ROOM)
            .saturating_add(file_bytes.saturating_mul(3)),
    );
    limits
}

/// The width and height an image file's header gives (a PNG's IHDR; other formats through the
/// decoder's header read under [`decoder_limits`] for no pixels), or `None` when it cannot be
/// read. For size checks that must not decode: a keep-out mask's header read with the
/// decoder's default cap inflated a colour-profile bomb to 520 MB.
pub(crate) fn header_size<R: BufRead + Seek>(mut r: R) -> Option<(u32, u32)> {
    let start = r.stream_position().ok()?;
    let file_bytes = r.seek(SeekFrom::End(0)).ok()?.saturating_sub(start);
    r.seek(SeekFrom::Start(start)).ok()?;
    if let Some(size) = png_ihdr_size(&mut r).ok()? {
        return Some(size);
    }
    r.seek(SeekFrom::Start(start)).ok()?;
    let mut reader = ImageReader::new(r).with_guessed_format().ok()?;
    reader.limits(decoder_limits(0, file_bytes));
    reader.into_dimensions().ok()
}

/// The width and height in a PNG's IHDR chunk (the signature, then the IHDR chunk first, as
/// the format requires), read from the stream's position; `None` when the bytes there are not
/// that. The stream is left wherever the read stopped.
fn png_ihdr_size<R: std::io::Read>(r: &mut R) -> std::io::Result<Option<(u32, u32)>> {
    let mut head = [0u8; 24];
    let mut got = 0;
    while got < head.len() {
        match r.read(&mut head[got..])? {
            0 => return Ok(None),
            n => got += n,
        }
    }
    if &head[..8] != b"\x89PNG\r\n\x1a\n" || &head[12..16] != b"IHDR" {
        return Ok(None);
    }
    let word = |i: usize| u32::from_be_bytes([head[i], head[i + 1], head[i + 2], head[i + 3]]);
    Ok(Some((word(16), word(20))))
}

/// Whether the file at `path` begins as a PNG or PNM image, by the content guess
/// [`decode_and_classify`] starts with (the formats ccpp decodes); `false` also when it
/// cannot be read.
pub(crate) fn decodable_format(path: &Path) -> bool {
    ImageReader::open(path)
        .and_then(ImageReader::with_guessed_format)
        .is_ok_and(|r| {
            matches!(
                r.format(),
                Some(image::ImageFormat::Png | image::ImageFormat::Pnm)
            )
        })
}

/// The PNG decoder's words with its chunk types as their names: `ChunkType { type: IHDR,
/// critical: true, private: false, reserved: false, safecopy: false }` (the decoder's debug
/// text of a chunk, in its CRC errors) becomes `IHDR` (hostile pass).
fn chunk_names(text: &str) -> String {
    const OPEN: &str = "ChunkType { type: ";
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(OPEN) {
        out.push_str(&rest[..i]);
        let after = &rest[i + OPEN.len()..];
        let (Some(end), Some(comma)) = (after.find('}'), after.find(',')) else {
            out.push_str(&rest[i..]);
            return out;
        };
        out.push_str(after[..comma.min(end)].trim());
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    out
}

/// Largest file [`tight_pnm_header`] reads whole to rewrite its header (a larger one is left
/// to the decoder, which then names the header it cannot read).
const TIGHT_PNM_MAX_BYTES: u64 = 256 << 20;

/// The PNM image in `r` (from its current position) with a plain header, when its header has
/// a comment right after a token (`P5\n50#c\n40\n255\n`: Netpbm allows a comment anywhere
/// in the header, the decoder only after whitespace); `None` (and `r` back where it was) for
/// any other file, which is decoded as it is. The raster starts after the whitespace that
/// ends the last token, or after the end of the comment right after it.
pub(crate) fn tight_pnm_header<R: BufRead + Seek>(r: &mut R) -> std::io::Result<Option<Vec<u8>>> {
    let start = r.stream_position()?;
    let mut head = Vec::new();
    r.by_ref().take(4096).read_to_end(&mut head)?;
    r.seek(SeekFrom::Start(start))?;
    let Some(plain_head) = plain_pnm_header(&head) else {
        return Ok(None);
    };
    let (header, raster_at) = plain_head;
    let len = r.seek(SeekFrom::End(0))?.saturating_sub(start);
    r.seek(SeekFrom::Start(start))?;
    if len > TIGHT_PNM_MAX_BYTES {
        return Ok(None);
    }
    let mut all = Vec::new();
    r.read_to_end(&mut all)?;
    r.seek(SeekFrom::Start(start))?;
    let mut out = header.into_bytes();
    out.extend_from_slice(all.get(raster_at..).unwrap_or_default());
    Ok(Some(out))
}

/// The plain header (`P5\nW H\nMAX\n`) of a PNM header `head` (P1-P6) that has a comment
/// right after one of its tokens, and where its raster starts; `None` otherwise.
fn plain_pnm_header(head: &[u8]) -> Option<(String, usize)> {
    let kind = match head {
        [b'P', d @ b'1'..=b'6', ..] => *d,
        _ => return None,
    };
    let count = if matches!(kind, b'1' | b'4') { 2 } else { 3 };
    let mut tokens: Vec<&[u8]> = Vec::new();
    let mut tight = false;
    let mut i = 2;
    // (the magic number itself may be followed by a comment at once)
    if head.get(i) == Some(&b'#') {
        tight = true;
    }
    let skip_comment = |i: usize| -> Option<usize> {
        let nl = head[i..].iter().position(|&b| b == b'\n')?;
        Some(i + nl + 1)
    };
    loop {
        match head.get(i)? {
            b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c => i += 1,
            b'#' => i = skip_comment(i)?,
            _ => {
                let s = i;
                while head
                    .get(i)
                    .is_some_and(|b| !b.is_ascii_whitespace() && *b != b'#')
                {
                    i += 1;
                }
                let token = &head[s..i];
                if !token.iter().all(u8::is_ascii_digit) || token.len() > 10 {
                    return None;
                }
                tokens.push(token);
                let at_comment = head.get(i)? == &b'#';
                tight |= at_comment;
                if tokens.len() == count {
                    let raster = if at_comment { skip_comment(i)? } else { i + 1 };
                    if !tight {
                        return None;
                    }
                    let t = |k: usize| String::from_utf8_lossy(tokens[k]).into_owned();
                    let header = if count == 2 {
                        format!("P{}\n{} {}\n", kind as char, t(0), t(1))
                    } else {
                        format!("P{}\n{} {}\n{}\n", kind as char, t(0), t(1), t(2))
                    };
                    return Some((header, raster));
                }
            }
        }
    }
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
        message: one_line(&chunk_names(&e.to_string())),
    };
    let io_err = |e: std::io::Error| MapError::Io {
        path: path.to_path_buf(),
        source: e,
    };
    let reader = reader.with_guessed_format().map_err(io_err)?;
    let Some(format) = reader.format() else {
        // A map_server YAML named otherwise (`map.txt`) is read as an image, by its name: said
        // as such (it was "not a PNG or PNM/PGM image"; hostile pass).
        let mut head = Vec::new();
        let yaml_like = reader
            .into_inner()
            .take(4096)
            .read_to_end(&mut head)
            .is_ok()
            && String::from_utf8_lossy(&head)
                .lines()
                .any(|l| l.trim_start_matches('\u{feff}').starts_with("image:"));
        let yaml_named = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"));
        let message = if yaml_like && yaml_named {
            // Reached as the `image:` of another YAML (or itself): the advice to rename it
            // was wrong (hostile pass).
            "not a PNG or PNM/PGM image: it is a map_server YAML, and a map YAML's `image:` names the image file (PGM or PNG), not a YAML"
        } else if yaml_like {
            "not a PNG or PNM/PGM image: it reads as a map_server YAML (an `image:` line), but a map's YAML is known by its name, which must end in .yaml or .yml; rename it"
        } else {
            "not a PNG or PNM/PGM image (unrecognised content)"
        };
        return Err(MapError::Decode {
            path: path.to_path_buf(),
            message: message.to_owned(),
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
    // The checks below read ahead over the same stream, which then goes back to where the
    // image starts; the cheap one (the header) first.
    let mut inner = reader.into_inner();
    let start = inner.stream_position().map_err(io_err)?;
    let file_bytes = inner
        .seek(SeekFrom::End(0))
        .map_err(io_err)?
        .saturating_sub(start);
    inner.seek(SeekFrom::Start(start)).map_err(io_err)?;
    // The size from the header, read under the room's cap alone (a PNG's header read inflates
    // the chunks before its image data). A PNG's size is read from its IHDR first: the
    // decoder's header read allocates a row, so a PNG claiming 2147483647 px across failed as
    // "Memory limit exceeded" instead of being named too large.
    // A PAM's header lines are read whole, by the decoder and by the maxval check below: a
    // comment line of 100 MiB in a 4 x 4 px PAM took 108 MB before the file was refused.
    if format == image::ImageFormat::Pnm {
        if let Some(n) = long_pam_header_line(&mut inner).map_err(io_err)? {
            return Err(MapError::Decode {
                path: path.to_path_buf(),
                message: format!(
                    "a PAM header line is longer than {n} bytes; header lines and comments that \
                     long are refused"
                ),
            });
        }
        inner.seek(SeekFrom::Start(start)).map_err(io_err)?;
    }
    let (width, height) = match png_ihdr_size(&mut inner).map_err(io_err)? {
        Some(size) if format == image::ImageFormat::Png => size,
        _ => {
            inner.seek(SeekFrom::Start(start)).map_err(io_err)?;
            let mut header = ImageReader::with_format(&mut inner, format);
            header.limits(decoder_limits(0, file_bytes));
            header.into_dimensions().map_err(image_err)?
        }
    };
    let pixels = u64::from(width) * u64::from(height);
    if let Some(max) = max_pixels {
        if pixels > max {
            return Err(MapError::TooLarge {
                path: path.to_path_buf(),
                width,
                height,
                max_pixels: max,
            });
        }
    }
    // A file far larger than its pixels can take holds that much metadata (a PNG chunk, a PNM
    // comment), which the decoder keeps in memory: a 40 x 30 px PNG with a 500 MiB `eXIf`
    // chunk took 1 GB under `--max-memory 20`.
    let most = pixels
        .saturating_mul(FILE_BYTES_PER_PIXEL)
        .saturating_add(METADATA_ROOM);
    if file_bytes > most {
        return Err(MapError::Decode {
            path: path.to_path_buf(),
            message: format!(
                "the file is {file_bytes} bytes for {width} x {height} px, more than such an \
                 image takes with {} MiB of metadata ({most} bytes); metadata or comments that \
                 large are refused",
                METADATA_ROOM >> 20
            ),
        });
    }
    inner.seek(SeekFrom::Start(start)).map_err(io_err)?;
    // A PNM sample above its maxval: Netpbm forbids it, and the decoder rescaled it beyond
    // white, so a malformed file read as free floor.
    if format == image::ImageFormat::Pnm {
        if let Some((sample, maxval)) = pnm_sample_over_maxval(&mut inner).map_err(io_err)? {
            return Err(MapError::Decode {
                path: path.to_path_buf(),
                // (a sample of 23 digits was shown as 4294967295, the largest u32)
                message: if sample == u64::MAX {
                    format!("a sample too large to hold (over {}) exceeds the image's maxval {maxval} (a malformed PNM)", u64::MAX - 1)
                } else {
                    format!("sample {sample} exceeds the image's maxval {maxval} (a malformed PNM)")
                },
            });
        }
        inner.seek(SeekFrom::Start(start)).map_err(io_err)?;
    }
    // The decoder's cap follows the image's own size: its default (512 MiB) refused a 24000 x
    // 24000 PNG the caller's budget admits (`--max-memory 60000`: "Memory limit exceeded"),
    // and let a small image's colour profile inflate to 512 MiB. Without a budget
    // (`max_pixels: None`) the size the header claims is not checked, so the cap stays at
    // most the decoder's default: a header claiming 5 x 4294901764 px aborted on a 21 GB
    // allocation (found by the fuzz smoke).
    let mut limits = decoder_limits(pixels, file_bytes);
    if max_pixels.is_none() {
        let default = image::Limits::default().max_alloc;
        limits.max_alloc = limits.max_alloc.min(default);
    }
    // The decoded buffer is allocated whole before any pixel is read, and a failed allocation
    // aborts the process: it is asked for here first, fallibly (a 21-byte PGM claiming
    // 100000 x 100000 px, with `--max-memory` raised to admit it, aborted under a 3 GB
    // address-space limit instead of being refused).
    // (the decoder that will decode, so its header is read once; then the checks
    // `ImageReader::decode` makes)
    let mut reader = ImageReader::with_format(inner, format);
    reader.limits(limits.clone());
    let mut decoder = reader.into_decoder().map_err(image_err)?;
    let total = decoder.total_bytes();
    let mut probe: Vec<u8> = Vec::new();
    if usize::try_from(total).map_or(true, |n| probe.try_reserve_exact(n).is_err()) {
        return Err(MapError::Decode {
            path: path.to_path_buf(),
            message: format!(
                "its {width} x {height} pixels take {total} bytes decoded, which cannot be allocated"
            ),
        });
    }
    drop(probe);
    limits.reserve(total).map_err(image_err)?;
    decoder.set_limits(limits).map_err(image_err)?;
    let img = DynamicImage::from_decoder(decoder).map_err(image_err)?;
    let width = img.width() as usize;
    let height = img.height() as usize;
    let cells = classify_image(&img, t);
    let alpha_differs = alpha_averaged_differs(&img, t, &cells);
    drop(img);
    Ok(Classified {
        width,
        height,
        cells,
        alpha_differs,
    })
}

/// The first sample of a PNM image (`P2`, `P3`, `P5`, `P6`, `P7`) above the header's maxval,
/// with the maxval; `None` when there is none, for bitmaps (`P1`, `P4`) and for a header
/// the decoder will refuse anyway. Reads from the stream's position to the raster's end.
fn pnm_sample_over_maxval<R: BufRead>(r: &mut R) -> std::io::Result<Option<(u64, u32)>> {
    let mut magic = [0u8; 2];
    if r.read_exact(&mut magic).is_err() {
        return Ok(None);
    }
    let (ascii, mut channels) = match &magic {
        b"P2" => (true, 1u64),
        b"P3" => (true, 3),
        b"P5" | b"P7" => (false, 1),
        b"P6" => (false, 3),
        _ => return Ok(None),
    };
    let [w, h, maxval] = if &magic == b"P7" {
        // PAM: `KEY value` lines up to `ENDHDR`.
        let mut fields = [0u64; 3];
        loop {
            let mut line = Vec::new();
            if r.read_until(b'\n', &mut line)? == 0 {
                return Ok(None);
            }
            let line = String::from_utf8_lossy(&line);
            let mut words = line.split_whitespace();
            let key = words.next().unwrap_or("");
            let value = words.next().and_then(|v| v.parse::<u64>().ok());
            match (key, value) {
                ("ENDHDR", _) => break,
                ("WIDTH", Some(v)) => fields[0] = v,
                ("HEIGHT", Some(v)) => fields[1] = v,
                ("MAXVAL", Some(v)) => fields[2] = v,
                ("DEPTH", Some(v)) => channels = v,
                _ => {}
            }
        }
        fields
    } else {
        // Header: width, height, maxval, with `#` comments, then one whitespace byte.
        let mut fields = [0u64; 3];
        for f in &mut fields {
            match header_number(r)? {
                Some(v) => *f = v,
                None => return Ok(None),
            }
        }
        fields
    };
    if maxval == 0 || maxval > 65535 {
        return Ok(None);
    }
    let samples = w.saturating_mul(h).saturating_mul(channels);
    let over = |v: u64| (v > maxval).then_some((v, maxval as u32));
    if ascii {
        for _ in 0..samples {
            match header_number(r)? {
                Some(v) => {
                    if let Some(o) = over(v) {
                        return Ok(Some(o));
                    }
                }
                None => return Ok(None),
            }
        }
        return Ok(None);
    }
    if maxval == 255 || maxval == 65535 {
        return Ok(None);
    }
    let wide = maxval > 255;
    let mut left = if wide {
        samples.saturating_mul(2)
    } else {
        samples
    };
    let mut pending: Option<u8> = None;
    while left > 0 {
        let buf = r.fill_buf()?;
        if buf.is_empty() {
            return Ok(None);
        }
        let take = buf.len().min(usize::try_from(left).unwrap_or(usize::MAX));
        for &b in &buf[..take] {
            let v = if wide {
                match pending.take() {
                    None => {
                        pending = Some(b);
                        continue;
                    }
                    Some(hi) => u64::from(hi) << 8 | u64::from(b),
                }
            } else {
                u64::from(b)
            };
            if let Some(o) = over(v) {
                return Ok(Some(o));
            }
        }
        r.consume(take);
        left -= take as u64;
    }
    Ok(None)
}

/// The next decimal number of a PNM header (or plain raster), skipping whitespace and `#`
/// comments, and the one byte that ends it; `None` at the end or at anything else.
fn header_number<R: BufRead>(r: &mut R) -> std::io::Result<Option<u64>> {
    let mut byte = [0u8; 1];
    // Skip to the first digit.
    loop {
        if r.read(&mut byte)? == 0 {
            return Ok(None);
        }
        match byte[0] {
            b'#' => skip_line(r)?,
            b if b.is_ascii_whitespace() => {}
            b if b.is_ascii_digit() => break,
            _ => return Ok(None),
        }
    }
    let mut v = u64::from(byte[0] - b'0');
    loop {
        if r.read(&mut byte)? == 0 {
            return Ok(Some(v));
        }
        if !byte[0].is_ascii_digit() {
            // The whitespace (or comment start) after the number: the binary raster begins
            // right after one whitespace byte, so nothing more is read.
            if byte[0] == b'#' {
                skip_line(r)?;
            }
            return Ok(Some(v));
        }
        v = v
            .saturating_mul(10)
            .saturating_add(u64::from(byte[0] - b'0'));
    }
}

/// Longest header line of a PAM (`P7`) file ccpp reads, in bytes.
const PAM_LINE_MAX: u64 = 64 << 10;

/// For a PAM (`P7`) file at the stream's position, `Some(PAM_LINE_MAX)` when a header line
/// before `ENDHDR` is longer than [`PAM_LINE_MAX`]; `None` otherwise, and for other files. Reads
/// without keeping more than a line's start; the stream is left wherever the read stopped.
fn long_pam_header_line<R: BufRead>(r: &mut R) -> std::io::Result<Option<u64>> {
    let mut magic = [0u8; 3];
    if r.read_exact(&mut magic).is_err() || &magic[..2] != b"P7" {
        return Ok(None);
    }
    let mut line: Vec<u8> = Vec::new();
    loop {
        // One line, keeping at most its first 16 bytes (enough to see `ENDHDR`).
        line.clear();
        let mut len = 0u64;
        loop {
            let buf = r.fill_buf()?;
            if buf.is_empty() {
                return Ok(None);
            }
            let (n, end) = match buf.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (buf.len(), false),
            };
            let keep = n.min(16usize.saturating_sub(line.len()));
            line.extend_from_slice(&buf[..keep]);
            len += n as u64;
            r.consume(n);
            if len > PAM_LINE_MAX {
                return Ok(Some(PAM_LINE_MAX));
            }
            if end {
                break;
            }
        }
        if line.trim_ascii().starts_with(b"ENDHDR") {
            return Ok(None);
        }
    }
}

/// Reads past the next `\n` (or to the end) without keeping what it reads: a PNM header
/// comment of 500 MiB was read into memory whole.
fn skip_line<R: BufRead>(r: &mut R) -> std::io::Result<()> {
    loop {
        let buf = r.fill_buf()?;
        if buf.is_empty() {
            return Ok(());
        }
        if let Some(i) = buf.iter().position(|&b| b == b'\n') {
            r.consume(i + 1);
            return Ok(());
        }
        let n = buf.len();
        r.consume(n);
    }
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

/// The pixels of an 8-bit image with alpha that ROS `map_server` classifies otherwise than
/// `cells` in trinary mode: its loaders (ROS 1 `image_loader.cpp`, Nav2 `map_io.cpp`) average
/// the alpha channel in with the colour channels there (`(R + G + B + A) / 4`, `(L + A) / 2`),
/// which the ROS docs do not say and ccpp does not do (README, Maps). On an opaque RGBA map
/// the 205 grey of unknown pixels then reads 217.5, free: `nobleo_basement`'s unknown 64 %.
/// 0 in other modes and for other images.
fn alpha_averaged_differs(img: &DynamicImage, t: &Thresholds, cells: &[Cell]) -> usize {
    if t.mode != MapMode::Trinary {
        return 0;
    }
    match img {
        DynamicImage::ImageRgba8(b) => {
            let lut = mean_lut(t, 4);
            b.as_raw()
                .chunks_exact(4)
                .zip(cells)
                .filter(|(p, &c)| lut[rgb_sum(p) + usize::from(p[3])] != c)
                .count()
        }
        DynamicImage::ImageLumaA8(b) => {
            let lut = mean_lut(t, 2);
            b.as_raw()
                .chunks_exact(2)
                .zip(cells)
                .filter(|(p, &c)| lut[usize::from(p[0]) + usize::from(p[1])] != c)
                .count()
        }
        _ => 0,
    }
}

/// `R + G + B` of an 8-bit pixel (alpha, if any, is ignored).
#[inline]
fn rgb_sum(p: &[u8]) -> usize {
    usize::from(p[0]) + usize::from(p[1]) + usize::from(p[2])
}

/// Classification of every possible sum of `channels` 8-bit samples (0..=255 channels),
/// using the exact mean.
fn mean_lut(t: &Thresholds, channels: u16) -> Vec<Cell> {
    (0..=255 * channels)
        .map(|s| t.classify_level(f64::from(s) / f64::from(channels)))
        .collect()
}

/// Classification of every possible 8-bit `R + G + B` sum (0..=765), using the exact mean.
fn sum_lut(t: &Thresholds) -> Vec<Cell> {
    mean_lut(t, 3)
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

    #[test]
    fn chunk_types_are_named() {
        assert_eq!(
            super::chunk_names("CRC error: expected 0x8700c623 have 0x87d0c623 while decoding ChunkType { type: IHDR, critical: true, private: false, reserved: false, safecopy: false } chunk."),
            "CRC error: expected 0x8700c623 have 0x87d0c623 while decoding IHDR chunk."
        );
        assert_eq!(super::chunk_names("plain"), "plain");
        assert_eq!(
            super::chunk_names("ChunkType { type: x"),
            "ChunkType { type: x"
        );
    }

    use super::*;

    fn load(bytes: &[u8]) -> Result<crate::map::LoadedMap, MapError> {
        crate::map::load_map_bytes(
            Path::new("m.pgm"),
            None,
            bytes,
            &crate::map::LoadOptions::default(),
        )
    }

    /// Netpbm allows a comment anywhere in a header, also right after a token (`50#c`); the
    /// decoder refused those ("Non-ASCII-digit character when parsing number in preamble":
    /// hostile pass). They load as the plain header does.
    #[test]
    fn pnm_headers_with_a_comment_right_after_a_token_are_read() {
        use crate::map::{load_map_bytes, LoadOptions};
        let raster = [0u8, 254, 254, 0, 254, 0];
        let load = |head: &[u8]| {
            let mut bytes = head.to_vec();
            bytes.extend_from_slice(&raster);
            load_map_bytes(Path::new("m.pgm"), None, &bytes, &LoadOptions::default())
                .map(|m| m.grid)
        };
        let plain = load(b"P5\n3 2\n255\n").unwrap();
        for head in [
            &b"P5\n3#c\n2\n255\n"[..],
            b"P5\n3 2\n255#c\n",
            b"P5#c1\n3#c2\n 2 #c3\n255#c4\n",
            b"P5 # spaced\n3 2 255\n",
        ] {
            assert_eq!(
                load(head).unwrap(),
                plain,
                "{}",
                String::from_utf8_lossy(head)
            );
        }
        // Only a header with a tight comment is rewritten; the raster starts after the
        // comment that ends the last token.
        assert_eq!(plain_pnm_header(b"P5\n3 2\n255\n"), None);
        assert_eq!(
            plain_pnm_header(b"P5\n3 2\n255#c\nXY"),
            Some(("P5\n3 2\n255\n".to_string(), 13))
        );
        assert_eq!(
            plain_pnm_header(b"P4\n3#w\n2\nXY"),
            Some(("P4\n3 2\n".to_string(), 9))
        );
        // A malformed header is the decoder's to name.
        assert_eq!(plain_pnm_header(b"P5\n3#c\nx 255\n"), None);
    }

    /// A sample above the maxval (Netpbm forbids it) read as free floor: the decoder scaled
    /// it beyond white. It is refused, naming the sample; samples at the maxval load.
    #[test]
    fn pnm_samples_above_their_maxval_are_refused() {
        let over = |bytes: &[u8]| match load(bytes) {
            Err(MapError::Decode { message, .. }) => message,
            other => panic!("{other:?}"),
        };
        assert!(over(b"P5 2 1 100\n\x00\xc8").contains("sample 200 exceeds the image's maxval 100"));
        assert!(over(b"P2\n# c\n2 1\n100\n0 150\n").contains("sample 150"));
        // Beyond u32 as it is; beyond u64 as too large (it read "sample 4294967295").
        assert!(over(b"P2\n2 1\n100\n0 99999999999\n").contains("sample 99999999999 exceeds"));
        assert!(over(b"P2\n2 1\n100\n0 99999999999999999999999\n")
            .contains("a sample too large to hold"));
        assert!(
            over(b"P5 1 1 1000\n\x03\xe9").contains("sample 1001 exceeds the image's maxval 1000")
        );
        assert!(over(b"P6 1 1 100\n\x00\x00\x65").contains("sample 101"));
        assert!(over(
            b"P7\nWIDTH 2\nHEIGHT 1\nDEPTH 1\nMAXVAL 100\nTUPLTYPE GRAYSCALE\nENDHDR\n\x00\xfa"
        )
        .contains("sample 250"));
        // At the maxval, and the full ranges, load.
        for ok in [
            &b"P5 2 1 100\n\x00\x64"[..],
            b"P2 2 1 100 0 100",
            b"P5 2 1 255\n\x00\xff",
            b"P5 1 1 1000\n\x03\xe8",
            b"P5 # width\n2 # height\n1 255\n\x00\xfe",
            b"P7\nWIDTH 2\nHEIGHT 1\nDEPTH 1\nMAXVAL 100\nTUPLTYPE GRAYSCALE\nENDHDR\n\x00\x64",
        ] {
            load(ok).unwrap_or_else(|e| panic!("{e}"));
        }
    }

    /// Without a budget (`max_pixels: None`, as `load_map_bytes` with default options) the
    /// cap followed a header claiming 5 x 4294901764 px and the decoder aborted on a 21 GB
    /// allocation (found by the fuzz smoke): the cap then stays the decoder's default.
    #[test]
    fn a_huge_claimed_size_without_a_budget_is_an_error_not_an_abort() {
        let png = hex(
            "89504e470d0a1a0a0000000d4948445200000005ffff000408030000009adabe7100000009504c5445\
             000000ffffffcdcdcd7130916c0000000274ff4e53ff80080fb36a0000000f49444154789c6300\
             49454e44ae426082",
        );
        let t = Thresholds::default();
        let reader = ImageReader::new(std::io::Cursor::new(png));
        assert!(decode_and_classify(reader, Path::new("claim.png"), &t, None).is_err());
    }

    fn hex(s: &str) -> Vec<u8> {
        let s: String = s.split_whitespace().collect();
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
            .collect()
    }

    /// The decoder's default cap (512 MiB) refused a 24000 x 24000 PNG under
    /// `--max-memory 60000` ("Memory limit exceeded"), and let a 100 x 100 PNG's colour
    /// profile inflate to 500 MiB: the cap follows the image's size.
    #[test]
    fn the_decoder_cap_follows_the_image() {
        let default = image::Limits::default().max_alloc.unwrap();
        // A small image gets the room alone, far below the decoder's default.
        assert_eq!(
            decoder_limits(100 * 100, 0).max_alloc,
            Some(10_000 * 8 + DECODER_ROOM)
        );
        assert!(decoder_limits(100 * 100, 1 << 20).max_alloc.unwrap() < default / 16);
        // 24000 x 24000 grey pixels (576 MB decoded, over the default) fit.
        let px = 24_000u64 * 24_000;
        let cap = decoder_limits(px, 0).max_alloc.unwrap();
        assert!(cap >= px * DECODED_BYTES_MAX && cap > default, "{cap}");
        assert_eq!(decoder_limits(u64::MAX, 0).max_alloc, Some(u64::MAX));
    }
}
