//! PGM images (Netpbm's `pgm(5)`): binary `P5` and plain `P2`, `maxval` up to 65535 (two bytes
//! a sample, most significant first, above 255). Read a row at a time, so that memory is the
//! map's cells and one row whatever the file holds.

use std::io::{BufRead, ErrorKind};
use std::path::Path;

use super::map::MAX_CELLS;
use super::pixels::{Layout, Rules};
use super::{Cell, MapError};

/// What an image gives the map: its size and its cells, bottom row first.
pub(super) struct Decoded {
    pub width: usize,
    pub height: usize,
    pub cells: Vec<Cell>,
}

/// A PGM's pixel for each kind of cell: map_saver's values.
pub(super) fn pixel(cell: Cell) -> u8 {
    match cell {
        Cell::Occupied => 0,
        Cell::Free => 254,
        Cell::Unknown => 205,
    }
}

/// How every PGM [`encode`] writes starts (map_saver's comment names itself the same way).
pub(super) const CREATOR: &str = "P5\n# CREATOR: hilsim ";

/// The `P5` image of `cells` (`width` a row, bottom row first), top row first as PGM has it.
pub(super) fn encode(width: usize, height: usize, cells: &[Cell], resolution_m: f64) -> Vec<u8> {
    let mut out = format!("{CREATOR}{resolution_m} m/pix\n{width} {height}\n255\n").into_bytes();
    out.reserve(width * height);
    if width > 0 {
        for row in cells.chunks_exact(width).rev() {
            out.extend(row.iter().map(|&c| pixel(c)));
        }
    }
    out
}

/// Reads a PGM image from `input` (the file `path`) and makes its pixels cells by `rules`.
pub(super) fn decode(input: impl BufRead, path: &Path, rules: &Rules) -> Result<Decoded, MapError> {
    let mut r = Reader {
        input,
        path,
        line: 1,
    };
    let plain = match [r.byte()?, r.byte()?] {
        [Some(b'P'), Some(b'5')] => false,
        [Some(b'P'), Some(b'2')] => true,
        _ => return Err(r.fail("not a PGM image (it must start with P5 or P2)")),
    };
    let width = r.header_number("width")?;
    let height = r.header_number("height")?;
    let maxval = r.header_number("maxval")?;
    if width == 0 || height == 0 {
        return Err(r.fail(format!(
            "an image of {width} × {height} pixels holds no map"
        )));
    }
    if width.saturating_mul(height) > MAX_CELLS as u64 {
        return Err(r.fail(format!(
            "an image of {width} × {height} pixels is more than the {MAX_CELLS} cells a map may \
             have"
        )));
    }
    let max = u16::try_from(maxval)
        .ok()
        .filter(|&m| m > 0)
        .ok_or_else(|| r.fail(format!("maxval must be 1 to 65535, not {maxval}")))?;
    let (width, height) = (width as usize, height as usize);
    let layout = Layout {
        channels: 1,
        alpha: false,
        max,
    };
    let mut cells = vec![Cell::Unknown; width * height];
    let mut samples = vec![0u16; width];
    let wide = max > 255;
    let mut bytes = vec![
        0u8;
        if plain {
            0
        } else {
            width * (1 + usize::from(wide))
        }
    ];
    for row in 0..height {
        if plain {
            for sample in &mut samples {
                let v = r.number()?.ok_or_else(|| {
                    r.fail(format!("the pixels end in row {} of {height}", row + 1))
                })?;
                *sample = u16::try_from(v)
                    .ok()
                    .filter(|&v| v <= max)
                    .ok_or_else(|| r.fail(format!("a pixel of {v} is above maxval {max}")))?;
            }
        } else {
            r.input.read_exact(&mut bytes).map_err(|err| {
                if err.kind() == ErrorKind::UnexpectedEof {
                    r.fail(format!("the pixels end in row {} of {height}", row + 1))
                } else {
                    MapError::io(path, err)
                }
            })?;
            if wide {
                for (sample, pair) in samples.iter_mut().zip(bytes.chunks_exact(2)) {
                    *sample = u16::from_be_bytes([pair[0], pair[1]]);
                }
            } else {
                for (sample, &b) in samples.iter_mut().zip(&bytes) {
                    *sample = u16::from(b);
                }
            }
            if let Some(v) = samples.iter().find(|&&v| v > max) {
                return Err(r.fail(format!("a pixel of {v} is above maxval {max}")));
            }
        }
        // The image's first row is the map's top.
        let start = (height - 1 - row) * width;
        if let Some(out) = cells.get_mut(start..start + width) {
            rules.classify(&samples, layout, out);
        }
    }
    Ok(Decoded {
        width,
        height,
        cells,
    })
}

/// The header's (and a plain image's) tokens, with the line they are on.
struct Reader<'a, R> {
    input: R,
    path: &'a Path,
    line: usize,
}

impl<R: BufRead> Reader<'_, R> {
    fn fail(&self, message: impl Into<String>) -> MapError {
        MapError::format(self.path, Some(self.line), message)
    }

    fn byte(&mut self) -> Result<Option<u8>, MapError> {
        let buf = loop {
            match self.input.fill_buf() {
                Ok(buf) => break buf,
                Err(err) if err.kind() == ErrorKind::Interrupted => {}
                Err(err) => return Err(MapError::io(self.path, err)),
            }
        };
        let Some(&b) = buf.first() else {
            return Ok(None);
        };
        self.input.consume(1);
        if b == b'\n' {
            self.line += 1;
        }
        Ok(Some(b))
    }

    /// The next decimal number, after whitespace and `#` comments, and the one whitespace byte
    /// that ends it (before a binary raster, the only one); `None` at the end of the file.
    fn number(&mut self) -> Result<Option<u64>, MapError> {
        let mut b = self.byte()?;
        loop {
            match b {
                Some(b'#') => {
                    while !matches!(b, None | Some(b'\n' | b'\r')) {
                        b = self.byte()?;
                    }
                }
                Some(c) if c.is_ascii_whitespace() => b = self.byte()?,
                _ => break,
            }
        }
        let mut value: u64 = 0;
        let mut digits = 0;
        loop {
            match b {
                Some(c) if c.is_ascii_digit() => {
                    digits += 1;
                    // Ten digits hold any number a PGM may have; more is not a PGM.
                    if digits > 10 {
                        return Err(self.fail("a number of more than ten digits"));
                    }
                    value = value * 10 + u64::from(c - b'0');
                }
                None if digits == 0 => return Ok(None),
                None => return Ok(Some(value)),
                Some(c) if c.is_ascii_whitespace() && digits > 0 => return Ok(Some(value)),
                Some(c) => {
                    return Err(self.fail(format!(
                        "expected a number, found {:?}",
                        char::from(c).escape_default().to_string()
                    )))
                }
            }
            b = self.byte()?;
        }
    }

    fn header_number(&mut self, what: &str) -> Result<u64, MapError> {
        self.number()?
            .ok_or_else(|| self.fail(format!("the header ends before its {what}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::pixels::Mode;
    use proptest::prelude::*;

    const RULES: Rules = Rules {
        mode: Mode::Trinary,
        negate: false,
        occupied_thresh: 0.65,
        free_thresh: 0.196,
    };

    fn read(bytes: &[u8]) -> Result<Decoded, MapError> {
        decode(bytes, Path::new("map.pgm"), &RULES)
    }

    #[test]
    fn plain_and_binary_read_the_same_with_comments_anywhere_in_the_header() {
        use Cell::*;
        let plain = read(b"P2\n# c\n3 2 # c\n255\n0 254 205\n# c\n254 254 0\n").unwrap();
        let binary = read(b"P5 3\n2\n255\n\x00\xfe\xcd\xfe\xfe\x00").unwrap();
        for image in [&plain, &binary] {
            assert_eq!((image.width, image.height), (3, 2));
            // Bottom row first.
            assert_eq!(image.cells, [Free, Free, Occupied, Occupied, Free, Unknown]);
        }
    }

    #[test]
    fn sixteen_bit_samples_are_big_endian() {
        let image = read(b"P5 2 1 65535\n\x00\x00\xff\xff").unwrap();
        assert_eq!(image.cells, [Cell::Occupied, Cell::Free]);
    }

    #[test]
    fn encoded_images_decode_to_the_same_cells() {
        use Cell::*;
        let cells = [Free, Occupied, Unknown, Unknown, Free, Occupied];
        let bytes = encode(3, 2, &cells, 0.05);
        assert_eq!(read(&bytes).unwrap().cells, cells);
    }

    #[test]
    fn malformed_images_name_the_file_and_line() {
        let cases: [(&[u8], &str); 7] = [
            (b"P6 1 1 255\n\x00", "map.pgm:1: not a PGM"),
            (b"P2\n1\n", "map.pgm:3: the header ends before its height"),
            (
                b"P2 1 1 256\n300",
                "map.pgm:2: a pixel of 300 is above maxval 256",
            ),
            (
                b"P5 2 2 255\n\x00\x00\x00",
                "map.pgm:2: the pixels end in row 2 of 2",
            ),
            (b"P5 0 2 255\n", "holds no map"),
            (b"P5 100000 100000 255\n", "more than the 100000000 cells"),
            (b"P5 1 1 70000\n", "maxval must be 1 to 65535"),
        ];
        for (bytes, expected) in cases {
            let err = read(bytes).err().unwrap().to_string();
            assert!(err.contains(expected), "{err:?} lacks {expected:?}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..64)) {
            let _ = read(&bytes);
        }

        #[test]
        fn arbitrary_bytes_after_a_header_never_panic(
            plain in any::<bool>(),
            w in 1u32..6, h in 1u32..6, max in 1u32..70000,
            body in proptest::collection::vec(any::<u8>(), 0..80),
        ) {
            let mut bytes = format!("P{} {w} {h} {max}\n", if plain { 2 } else { 5 }).into_bytes();
            bytes.extend(body);
            if let Ok(image) = read(&bytes) {
                prop_assert_eq!(image.cells.len(), (w * h) as usize);
            }
        }
    }
}
