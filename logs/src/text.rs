//! A log file's text, gunzipped when it is gzipped.

use std::io::Read;
use std::path::Path;

use crate::LogError;

/// The most text a log may hold, after decompression: 2 GiB. A CARMEN log of a day's drive is a
/// few hundred MB; the cap keeps a corrupt or hostile gzip stream from filling memory.
pub const MAX_TEXT_BYTES: u64 = 2 << 30;

/// The text of the log at `path`, decompressed when it starts with gzip's magic bytes (whatever
/// its name: `.gz`, `.clf.gz` and a renamed file alike).
pub fn read_text(path: &Path) -> Result<String, LogError> {
    let name = path.display().to_string();
    let io = |source| LogError::Io {
        path: name.clone(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut magic = [0u8; 2];
    let mut got = 0;
    while got < 2 {
        let n = file.read(&mut magic[got..]).map_err(io)?;
        if n == 0 {
            break;
        }
        got += n;
    }
    let head = std::io::Cursor::new(magic[..got].to_vec());
    let raw = head.chain(file);
    let mut bytes = Vec::new();
    // One byte past the cap tells a file at the cap from one over it.
    if got == 2 && magic == [0x1f, 0x8b] {
        flate2::read::MultiGzDecoder::new(raw)
            .take(MAX_TEXT_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(io)?;
    } else {
        raw.take(MAX_TEXT_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(io)?;
    }
    if bytes.len() as u64 > MAX_TEXT_BYTES {
        return Err(LogError::TooLarge {
            path: name,
            limit: MAX_TEXT_BYTES,
        });
    }
    String::from_utf8(bytes).map_err(|_| LogError::NotText { path: name })
}
