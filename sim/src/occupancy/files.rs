//! A map's files: map_server's YAML and the image beside it, read and written.

use std::fs;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use hilsim_recording::{check_output_file, read_small_text, write_file_atomically, FileKind};

use super::cast_tables::CastTables;
use super::map::check_geometry;
use super::{pgm, png_image, yaml, MapError, OccupancyMap};

/// The largest map YAML read: 64 KiB; map_saver's is seven lines.
const MAX_YAML_BYTES: u64 = 64 << 10;

/// The first line of every YAML [`OccupancyMap::write`] writes: how a previous one is told from
/// a user's map (map_saver's, a hand-edited one), which is never replaced.
const YAML_FIRST_LINE: &str = "# An occupancy map written by hilsim\n";

/// A map YAML [`OccupancyMap::write`] wrote, as a single-file output recognises a previous one.
pub const MAP_YAML: FileKind = FileKind {
    name: "a map YAML written by hilsim",
    starts_with: YAML_FIRST_LINE.as_bytes(),
};

/// A map image [`OccupancyMap::write`] wrote, as a single-file output recognises a previous one.
pub const MAP_PGM: FileKind = FileKind {
    name: "a map image written by hilsim",
    starts_with: pgm::CREATOR.as_bytes(),
};

impl OccupancyMap {
    /// Reads a map_server map: its YAML (`image`, `resolution`, `origin: [x, y, yaw]`,
    /// `occupied_thresh`, `free_thresh`, `negate`, and `mode`: `trinary` (the default), `scale`
    /// or `raw`) and its image, at `image` relative to the YAML's directory: a PGM (`P5` or
    /// `P2`, `maxval` up to 65535) or a PNG (gray, gray and alpha, RGB or RGBA, 8 or 16 bits, or
    /// a palette). Pixels become cells as map_server makes them (see `pixels.rs`: `p = 1 -
    /// value/max` unless `negate`; occupied above `occupied_thresh`, free below `free_thresh`,
    /// unknown between). The image's first row is the map's top: `y` grows up from its last row,
    /// whose lower-left corner is at `origin`.
    ///
    /// A map whose origin has a yaw other than 0 is refused: map_server ignores the yaw in most
    /// versions (ROS 1's and ROS 2's, which only store it in the map's metadata), so the robot's
    /// logs were made against the unrotated map, and taking it would put the walls elsewhere.
    ///
    /// # Errors
    /// A file that cannot be read, YAML or an image that is not map_server's (naming the file,
    /// and the line where there is one), an image of more than [`super::MAX_CELLS`] pixels.
    pub fn load(yaml: &Path) -> Result<Self, MapError> {
        let text =
            read_small_text(yaml, MAX_YAML_BYTES, "a map_server map's YAML").map_err(from_input)?;
        let spec = yaml::parse(&text, yaml)?;
        let image = yaml
            .parent()
            .map_or_else(|| PathBuf::from(&spec.image), |dir| dir.join(&spec.image));
        let meta = fs::metadata(&image).map_err(|err| MapError::io(&image, err))?;
        if !meta.is_file() {
            return Err(MapError::format(&image, None, "not a regular file"));
        }
        let file = fs::File::open(&image).map_err(|err| MapError::io(&image, err))?;
        let mut input = BufReader::new(file);
        let head = input.fill_buf().map_err(|err| MapError::io(&image, err))?;
        let decoded = if head.starts_with(b"\x89PNG") {
            png_image::decode(input, &image, &spec.rules)?
        } else if head.starts_with(b"P5") || head.starts_with(b"P2") {
            pgm::decode(input, &image, &spec.rules)?
        } else {
            return Err(MapError::format(
                &image,
                None,
                "neither a PGM (P5, P2) nor a PNG image",
            ));
        };
        check_geometry(
            spec.resolution_m,
            spec.origin,
            decoded.width,
            decoded.height,
        )
        .map_err(|err| MapError::format(yaml, None, err.to_string()))?;
        Ok(Self {
            resolution_m: spec.resolution_m,
            origin: spec.origin,
            width: decoded.width,
            height: decoded.height,
            cells: decoded.cells,
            tables: CastTables::default(),
        })
    }

    /// Writes the map as map_server's YAML at `yaml` and a binary PGM beside it, named the
    /// YAML's stem + `.pgm`, as map_saver writes them: `mode: trinary`, occupied cells 0, free
    /// 254, unknown 205, thresholds 0.65 and 0.196; the resolution and origin in the shortest
    /// form that reads back exactly, so [`OccupancyMap::load`] gives this map back.
    ///
    /// Each file is written as every hilsim output is (`hilsim_recording::atomic`: a temporary
    /// sibling renamed over it), the image first so the YAML never names a missing one. A file
    /// already at either path is replaced only when it is empty or a previous map of hilsim's
    /// ([`MAP_YAML`], [`MAP_PGM`]); a user's map is never. See
    /// [`OccupancyMap::check_output`] to refuse before any work.
    ///
    /// # Errors
    /// A map of no cells, a path whose name is not UTF-8 or whose image would be the YAML
    /// itself, a path refused or a write that fails.
    pub fn write(&self, yaml: &Path) -> Result<(), MapError> {
        if self.cells.is_empty() {
            return Err(MapError::invalid(format!(
                "{}: a map of no cells cannot be written (map_server reads no empty image)",
                yaml.display()
            )));
        }
        let (image, name) = image_path(yaml)?;
        Self::check_output(yaml, &[])?;
        let pgm = pgm::encode(self.width, self.height, &self.cells, self.resolution_m);
        write_file_atomically(&image, &pgm)?;
        let text = format!(
            "{YAML_FIRST_LINE}{}",
            yaml::render(&name, self.resolution_m, self.origin)
        );
        write_file_atomically(yaml, text.as_bytes())?;
        Ok(())
    }

    /// Checks, before any work, that [`OccupancyMap::write`] may write `yaml` and its image:
    /// neither is one of `inputs`, and neither is a file other than a previous map of hilsim's.
    ///
    /// # Errors
    /// As [`OccupancyMap::write`]'s refusals.
    pub fn check_output(yaml: &Path, inputs: &[&Path]) -> Result<(), MapError> {
        let (image, _) = image_path(yaml)?;
        check_output_file(&image, MAP_PGM, inputs)?;
        check_output_file(yaml, MAP_YAML, inputs)?;
        Ok(())
    }
}

/// The image beside `yaml` and its name as the YAML gives it.
fn image_path(yaml: &Path) -> Result<(PathBuf, String), MapError> {
    let stem = yaml.file_stem().and_then(|s| s.to_str()).ok_or_else(|| {
        MapError::invalid(format!(
            "{}: a map's YAML needs a file name in UTF-8 (its image is named after it)",
            yaml.display()
        ))
    })?;
    let name = format!("{stem}.pgm");
    let image = yaml.with_file_name(&name);
    if image == yaml {
        return Err(MapError::invalid(format!(
            "{}: the map's image would be this very file; name the YAML *.yaml",
            yaml.display()
        )));
    }
    Ok((image, name))
}

/// A recording input's error, as the map's.
fn from_input(err: hilsim_recording::Error) -> MapError {
    match err.kind {
        hilsim_recording::ErrorKind::Io(error) => MapError::Io {
            path: err.path,
            error,
        },
        hilsim_recording::ErrorKind::Format(message) => MapError::Format {
            path: err.path,
            line: err.line,
            message,
        },
        other => MapError::format(&err.path, err.line, format!("{other:?}")),
    }
}
