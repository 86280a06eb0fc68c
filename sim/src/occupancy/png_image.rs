//! PNG images through the `png` crate: gray, gray and alpha, RGB and RGBA at 8 or 16 bits, and
//! palette and low-bit images expanded to those (a palette's transparency to alpha), as
//! map_server's image libraries read them.

use std::io::{BufRead, Seek};
use std::path::Path;

use png::{BitDepth, ColorType, Transformations};

use super::map::MAX_CELLS;
use super::pgm::Decoded;
use super::pixels::{Layout, Rules};
use super::{Cell, MapError};

/// The most memory the `png` crate may take for its own buffers (text chunks, ICC profiles,
/// a row): 64 MiB, its default.
const DECODER_BYTES: usize = 64 << 20;

/// An interlaced image is decoded whole before it is read (its passes cover rows in turn): at
/// most 512 MiB, a 100 M cell map at 16-bit gray with alpha and then some.
const INTERLACED_BYTES: usize = 512 << 20;

/// Reads a PNG image from `input` (the file `path`) and makes its pixels cells by `rules`.
pub(super) fn decode(
    input: impl BufRead + Seek,
    path: &Path,
    rules: &Rules,
) -> Result<Decoded, MapError> {
    let fail = |what: &dyn std::fmt::Display| MapError::format(path, None, format!("{what}"));
    let mut decoder = png::Decoder::new_with_limits(
        input,
        png::Limits {
            bytes: DECODER_BYTES,
        },
    );
    decoder.set_transformations(Transformations::EXPAND);
    let mut reader = decoder
        .read_info()
        .map_err(|err| fail(&format_args!("not a PNG image map_server can read: {err}")))?;
    let (width, height, interlaced) = {
        let info = reader.info();
        (info.width as usize, info.height as usize, info.interlaced)
    };
    if width == 0 || height == 0 {
        return Err(fail(&format_args!(
            "an image of {width} × {height} pixels holds no map"
        )));
    }
    if width.saturating_mul(height) > MAX_CELLS {
        return Err(fail(&format_args!(
            "an image of {width} × {height} pixels is more than the {MAX_CELLS} cells a map may \
             have"
        )));
    }
    let (color, depth) = reader.output_color_type();
    let (channels, alpha) = match color {
        ColorType::Grayscale => (1, false),
        ColorType::GrayscaleAlpha => (2, true),
        ColorType::Rgb => (3, false),
        ColorType::Rgba => (4, true),
        ColorType::Indexed => return Err(fail(&"a palette image the decoder did not expand")),
    };
    let wide = match depth {
        BitDepth::Eight => false,
        BitDepth::Sixteen => true,
        other => {
            return Err(fail(&format_args!(
                "{other:?}-bit samples the decoder did not expand"
            )))
        }
    };
    let layout = Layout {
        channels,
        alpha,
        max: if wide { u16::MAX } else { u16::from(u8::MAX) },
    };
    let row_bytes = width * channels * (1 + usize::from(wide));
    let mut cells = vec![Cell::Unknown; width * height];
    let mut samples = vec![0u16; width * channels];
    let mut put_row = |row: usize, bytes: &[u8]| {
        if wide {
            for (s, pair) in samples.iter_mut().zip(bytes.chunks_exact(2)) {
                *s = u16::from_be_bytes([pair[0], pair[1]]);
            }
        } else {
            for (s, &b) in samples.iter_mut().zip(bytes) {
                *s = u16::from(b);
            }
        }
        // The image's first row is the map's top.
        let start = (height - 1 - row) * width;
        if let Some(out) = cells.get_mut(start..start + width) {
            rules.classify(&samples, layout, out);
        }
    };
    let broken = |err: png::DecodingError| fail(&format_args!("a broken PNG image: {err}"));
    if interlaced {
        let size = reader
            .output_buffer_size()
            .filter(|&n| n <= INTERLACED_BYTES)
            .ok_or_else(|| {
                fail(&format_args!(
                    "an interlaced image this large (over {} MiB decoded) is not read; save it \
                     without interlacing",
                    INTERLACED_BYTES >> 20
                ))
            })?;
        let mut frame = vec![0u8; size];
        let info = reader.next_frame(&mut frame).map_err(broken)?;
        for (row, bytes) in frame.chunks_exact(info.line_size).take(height).enumerate() {
            put_row(row, bytes.get(..row_bytes).unwrap_or(bytes));
        }
    } else {
        for row in 0..height {
            let bytes = reader.next_row().map_err(broken)?.ok_or_else(|| {
                fail(&format_args!(
                    "the pixels end in row {} of {height}",
                    row + 1
                ))
            })?;
            put_row(row, bytes.data());
        }
    }
    Ok(Decoded {
        width,
        height,
        cells,
    })
}
