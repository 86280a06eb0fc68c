//! Reading map_server maps (YAML with a PGM or PNG image) and writing them back.

use std::fs;
use std::path::{Path, PathBuf};

use hilsim_sim::occupancy::{Cell, MapError, OccupancyMap};

const YAML: &str = "resolution: 0.1\norigin: [-1.0, 2.0, 0.0]\noccupied_thresh: 0.65\n\
                    free_thresh: 0.196\n";

/// Writes `image_bytes` as `name` and a YAML naming it (with `extra` lines) into `dir`.
fn map_files(dir: &Path, name: &str, image_bytes: &[u8], extra: &str) -> PathBuf {
    fs::write(dir.join(name), image_bytes).unwrap();
    let yaml = dir.join("map.yaml");
    fs::write(&yaml, format!("image: {name}\n{YAML}{extra}")).unwrap();
    yaml
}

/// An 8- or 16-bit PNG of `samples` (`channels` a pixel, rows top first).
fn png_bytes(
    width: u32,
    height: u32,
    color: png::ColorType,
    wide: bool,
    samples: &[u16],
) -> Vec<u8> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(color);
    encoder.set_depth(if wide {
        png::BitDepth::Sixteen
    } else {
        png::BitDepth::Eight
    });
    let data: Vec<u8> = if wide {
        samples.iter().flat_map(|v| v.to_be_bytes()).collect()
    } else {
        samples.iter().map(|&v| v as u8).collect()
    };
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(&data).unwrap();
    writer.finish().unwrap();
    out
}

/// The map's cells, top row first, as letters: `#` occupied, `.` free, `?` unknown.
fn picture(map: &OccupancyMap) -> Vec<String> {
    let (w, h) = map.size();
    (0..h)
        .rev()
        .map(|iy| {
            (0..w)
                .map(|ix| match map.cell(ix, iy).unwrap() {
                    Cell::Occupied => '#',
                    Cell::Free => '.',
                    Cell::Unknown => '?',
                })
                .collect()
        })
        .collect()
}

fn load(yaml: &Path) -> Result<OccupancyMap, MapError> {
    OccupancyMap::load(yaml)
}

#[test]
fn binary_and_plain_pgm_read_the_same_map() {
    let dir = tempfile::tempdir().unwrap();
    // Rows top first: black, white, map_saver's unknown grey.
    let p5 = b"P5\n3 2\n255\n\x00\xfe\xcd\xfe\xfe\x00";
    let p2 = b"P2\n# plain\n3 2\n255\n0 254 205\n254 254 0\n";
    for (name, bytes) in [("a.pgm", &p5[..]), ("b.pgm", &p2[..])] {
        let map = load(&map_files(dir.path(), name, bytes, "negate: 0\n")).unwrap();
        assert_eq!(picture(&map), ["#.?", "..#"], "{name}");
        assert_eq!(map.resolution_m(), 0.1);
        assert_eq!(map.origin(), [-1.0, 2.0]);
        assert_eq!(map.size(), (3, 2));
    }
}

#[test]
fn negate_swaps_black_and_white() {
    let dir = tempfile::tempdir().unwrap();
    let yaml = map_files(
        dir.path(),
        "m.pgm",
        b"P5 3 1 255\n\x00\xfe\x32",
        "negate: 1\n",
    );
    // Negated, p is the shade: 0 free, 254 occupied, 50 (p = 0.196) unknown.
    assert_eq!(picture(&load(&yaml).unwrap()), [".#?"]);
}

#[test]
fn the_top_left_pixel_is_the_top_left_of_the_world() {
    let dir = tempfile::tempdir().unwrap();
    // 4 × 3, one black pixel: the first of the first row.
    let mut bytes = b"P5 4 3 255\n".to_vec();
    bytes.extend([0u8].iter().chain(&[254u8; 11]));
    let map = load(&map_files(dir.path(), "m.pgm", &bytes, "negate: 0\n")).unwrap();
    // Origin (-1, 2), 0.1 m cells: the map spans x -1..-0.6, y 2..2.3; top-left cell is
    // x -1..-0.9, y 2.2..2.3.
    assert_eq!(map.cell_at([-0.95, 2.25]), Cell::Occupied);
    assert_eq!(map.cell(0, 2), Some(Cell::Occupied));
    assert_eq!(map.cell_at([-0.95, 2.05]), Cell::Free);
    assert_eq!(map.cell_at([-0.65, 2.25]), Cell::Free);
    assert_eq!(map.cell_at([-1.05, 2.25]), Cell::Unknown, "outside the map");
}

#[test]
fn thresholds_decide_between_occupied_unknown_and_free() {
    let dir = tempfile::tempdir().unwrap();
    // With occupied 0.5 and free 0.3: p = (255 - v)/255.
    // v = 127: p 0.502 occupied; 128: 0.498 unknown; 178: 0.302 unknown; 179: 0.298 free.
    let yaml = dir.path().join("t.yaml");
    fs::write(dir.path().join("t.pgm"), b"P5 4 1 255\n\x7f\x80\xb2\xb3").unwrap();
    fs::write(
        &yaml,
        "image: t.pgm\nresolution: 1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.5\n\
         free_thresh: 0.3\n",
    )
    .unwrap();
    assert_eq!(picture(&load(&yaml).unwrap()), ["#??."]);
}

#[test]
fn png_gray_alpha_rgb_and_sixteen_bit_read_as_map_server_reads_them() {
    use png::ColorType::*;
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, png::ColorType, bool, Vec<u16>, &str); 5] = [
        ("g8.png", Grayscale, false, vec![0, 254, 205], "#.?"),
        ("g16.png", Grayscale, true, vec![0, 65535, 52685], "#.?"),
        // Black opaque, white opaque, white transparent: trinary averages alpha in, so opaque
        // black is p = 0.5, unknown (map_server's own rule), and transparent white too.
        (
            "ga.png",
            GrayscaleAlpha,
            false,
            vec![0, 255, 255, 255, 255, 0],
            "?.?",
        ),
        // Pure red is a mean of 85, p 0.667; grey 200: p 0.216, unknown.
        (
            "rgb.png",
            Rgb,
            false,
            vec![255, 0, 0, 255, 255, 255, 200, 200, 200],
            "#.?",
        ),
        (
            "rgba16.png",
            Rgba,
            true,
            vec![
                0, 0, 0, 65535, 65535, 65535, 65535, 65535, 65535, 65535, 65535, 0,
            ],
            "#.?",
        ),
    ];
    for (name, color, wide, samples, expected) in cases {
        let bytes = png_bytes(3, 1, color, wide, &samples);
        let map = load(&map_files(dir.path(), name, &bytes, "negate: 0\n")).unwrap();
        assert_eq!(picture(&map), [expected], "{name}");
    }
}

#[test]
fn png_modes_scale_and_raw_and_negate() {
    use png::ColorType::*;
    let dir = tempfile::tempdir().unwrap();
    // Scale: alpha is not averaged; a translucent pixel is unknown.
    let bytes = png_bytes(3, 1, GrayscaleAlpha, false, &[0, 255, 255, 255, 0, 128]);
    let yaml = map_files(dir.path(), "s.png", &bytes, "negate: 0\nmode: scale\n");
    assert_eq!(picture(&load(&yaml).unwrap()), ["#.?"]);
    // Raw: the value is percent occupancy, negate or not.
    let bytes = png_bytes(4, 1, Grayscale, false, &[0, 100, 50, 255]);
    for negate in ["0", "1"] {
        let yaml = map_files(
            dir.path(),
            "r.png",
            &bytes,
            &format!("negate: {negate}\nmode: raw\n"),
        );
        assert_eq!(picture(&load(&yaml).unwrap()), [".#??"], "negate {negate}");
    }
    // Negate in trinary mode on a PNG.
    let bytes = png_bytes(2, 1, Grayscale, false, &[0, 255]);
    let yaml = map_files(dir.path(), "n.png", &bytes, "negate: 1\n");
    assert_eq!(picture(&load(&yaml).unwrap()), [".#"]);
}

#[test]
fn an_interlaced_png_reads_as_the_plain_one() {
    // A 3 × 2 gray Adam7 PNG of the rows [0, 254, 205] and [254, 254, 0], made by hand (the
    // `png` crate writes no interlaced images).
    const ADAM7: &[u8] = b"\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\x00\x03\x00\x00\x00\x02\x08\x00\x00\x00\x01\xcf\x18\x09\x50\x00\x00\x00\x12\x49\x44\x41\x54\x78\x9c\x63\x60\x60\x38\xcb\xf0\x8f\xe1\xdf\x3f\x06\x00\x0f\x91\x03\xc8\x77\x9c\x40\xd0\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82";
    let dir = tempfile::tempdir().unwrap();
    let yaml = map_files(dir.path(), "i.png", ADAM7, "negate: 0\n");
    assert_eq!(picture(&load(&yaml).unwrap()), ["#.?", "..#"]);
}

#[test]
fn the_image_is_found_beside_the_yaml_not_the_working_directory() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("maps");
    fs::create_dir(&sub).unwrap();
    let yaml = map_files(&sub, "m.pgm", b"P2 1 1 255 0", "negate: 0\n");
    assert_eq!(picture(&load(&yaml).unwrap()), ["#"]);
}

#[test]
fn malformed_maps_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let name = |p: &str| d.join(p).display().to_string();
    let cases: [(&str, &[u8], &str, String); 6] = [
        (
            "missing.pgm",
            b"",
            "negate: 0\n",
            format!("{}: ", name("gone.pgm")),
        ),
        (
            "t.pgm",
            b"P5 2 2 255\n\x00",
            "negate: 0\n",
            format!("{}:2: the pixels end", name("t.pgm")),
        ),
        (
            "x.bmp",
            b"BM\x00\x00",
            "negate: 0\n",
            format!("{}: neither a PGM", name("x.bmp")),
        ),
        (
            "p.png",
            b"\x89PNG\r\n\x1a\n\x00\x00",
            "negate: 0\n",
            format!("{}: not a PNG image", name("p.png")),
        ),
        (
            "y.pgm",
            b"P2 1 1 255 0",
            "negate: maybe\n",
            format!("{}:6: `negate`", name("map.yaml")),
        ),
        (
            "z.pgm",
            b"P2 1 1 255 0",
            "",
            format!("{}: no `negate`", name("map.yaml")),
        ),
    ];
    for (image, bytes, extra, expected) in cases {
        let yaml = map_files(d, image, bytes, extra);
        if image == "missing.pgm" {
            fs::write(&yaml, format!("image: gone.pgm\n{YAML}negate: 0\n")).unwrap();
        }
        let err = load(&yaml).unwrap_err().to_string();
        assert!(
            err.starts_with(&expected),
            "{err:?} does not start with {expected:?}"
        );
    }
    let err = load(&d.join("nothing.yaml")).unwrap_err().to_string();
    assert!(err.starts_with(&name("nothing.yaml")), "{err}");
    // A truncated PNG: its pixels cut off.
    let mut bytes = png_bytes(64, 64, png::ColorType::Rgb, false, &vec![7; 64 * 64 * 3]);
    bytes.truncate(bytes.len() / 2);
    let err = load(&map_files(d, "cut.png", &bytes, "negate: 0\n"))
        .unwrap_err()
        .to_string();
    assert!(err.starts_with(&name("cut.png")), "{err}");
    // A directory named as the image.
    fs::create_dir(d.join("dir.pgm")).unwrap();
    fs::write(
        d.join("map.yaml"),
        format!("image: dir.pgm\n{YAML}negate: 0\n"),
    )
    .unwrap();
    let err = load(&d.join("map.yaml")).unwrap_err().to_string();
    assert!(
        err.starts_with(&format!("{}: not a regular file", name("dir.pgm"))),
        "{err}"
    );
}

#[test]
fn a_rotated_origin_is_refused_saying_why() {
    let dir = tempfile::tempdir().unwrap();
    let yaml = map_files(dir.path(), "m.pgm", b"P2 1 1 255 0", "negate: 0\n");
    let text = fs::read_to_string(&yaml)
        .unwrap()
        .replace("2.0, 0.0]", "2.0, 0.3]");
    fs::write(&yaml, text).unwrap();
    let err = load(&yaml).unwrap_err().to_string();
    assert!(
        err.contains("map.yaml:3: `origin`'s yaw is 0.3") && err.contains("map_server ignores"),
        "{err}"
    );
}

#[test]
fn a_written_map_loads_back_identical() {
    let dir = tempfile::tempdir().unwrap();
    let mut map = OccupancyMap::new(0.05, [-12.345, 6.789_000_000_000_1], 7, 5).unwrap();
    for (i, cell) in [Cell::Occupied, Cell::Free]
        .into_iter()
        .cycle()
        .take(20)
        .enumerate()
    {
        assert!(map.set_cell((i * 3) % 7, i % 5, cell));
    }
    let yaml = dir.path().join("built map.yaml");
    map.write(&yaml).unwrap();
    assert!(dir.path().join("built map.pgm").is_file());
    let back = OccupancyMap::load(&yaml).unwrap();
    assert_eq!(back, map);
    // Written again over its own files.
    map.write(&yaml).unwrap();
    assert_eq!(OccupancyMap::load(&yaml).unwrap(), map);
}

#[test]
fn writing_never_replaces_a_users_map() {
    let dir = tempfile::tempdir().unwrap();
    let map = OccupancyMap::new(0.05, [0.0, 0.0], 2, 2).unwrap();
    // map_saver's files: a user's map, not hilsim's.
    let yaml = map_files(
        dir.path(),
        "map.pgm",
        b"P5\n# CREATOR: map_saver.cpp 0.050 m/pix\n1 1\n255\n\x00",
        "negate: 0\n",
    );
    let before = fs::read(&yaml).unwrap();
    let err = map.write(&yaml).unwrap_err().to_string();
    assert!(
        err.contains("map.pgm") && err.contains("refusing to replace it"),
        "{err}"
    );
    assert_eq!(fs::read(&yaml).unwrap(), before);
    // The YAML alone is a user's too.
    fs::remove_file(dir.path().join("map.pgm")).unwrap();
    let err = map.write(&yaml).unwrap_err().to_string();
    assert!(
        err.contains("map.yaml") && err.contains("refusing to replace it"),
        "{err}"
    );
    assert!(
        !dir.path().join("map.pgm").exists(),
        "nothing written before the refusal"
    );
    // An input of the command.
    let other = dir.path().join("other.yaml");
    let err = OccupancyMap::check_output(&other, &[&other]).err();
    assert!(err.is_none(), "absent: not the same file");
    map.write(&other).unwrap();
    let err = OccupancyMap::check_output(&other, &[&other])
        .unwrap_err()
        .to_string();
    assert!(err.contains("is an input"), "{err}");
}

#[test]
fn an_empty_map_or_a_yaml_named_pgm_is_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let empty = OccupancyMap::new(0.05, [0.0, 0.0], 0, 0).unwrap();
    assert!(empty.write(&dir.path().join("e.yaml")).is_err());
    let map = OccupancyMap::new(0.05, [0.0, 0.0], 1, 1).unwrap();
    let err = map
        .write(&dir.path().join("m.pgm"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("this very file"), "{err}");
}
