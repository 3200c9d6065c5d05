//! Reading the files a scene names, within stated limits: a FIFO or a device would block
//! forever, and an endless file or line would exhaust memory before any parser could object.

use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// The largest scene file read.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// The largest OBJ file read (the suite's 100k-triangle koala is 6 MB).
pub const MAX_OBJ_BYTES: u64 = 1 << 30;
/// The longest OBJ line read: real lines are tens of bytes.
pub const MAX_OBJ_LINE: usize = 64 << 10;

/// The bytes of `path`, a regular file of at most `limit` bytes; `what` names it in errors.
pub fn read_limited(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>> {
    let fail = |why: String| Error::scene(path, format!("cannot read the {what}: {why}"));
    let meta = std::fs::metadata(path).map_err(|e| fail(e.to_string()))?;
    if !meta.is_file() {
        return Err(fail("not a regular file".into()));
    }
    if meta.len() > limit {
        return Err(fail(format!("{} bytes, more than the limit of {limit}", meta.len())));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    let file = std::fs::File::open(path).map_err(|e| fail(e.to_string()))?;
    // The file may grow between the check and the read.
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|e| fail(e.to_string()))?;
    if bytes.len() as u64 > limit {
        return Err(fail(format!("more than the limit of {limit} bytes")));
    }
    Ok(bytes)
}

/// The first line (1-based) longer than `limit` bytes, if any.
pub fn overlong_line(bytes: &[u8], limit: usize) -> Option<usize> {
    bytes.split(|&b| b == b'\n').position(|line| line.len() > limit).map(|i| i + 1)
}

/// `text` cut to `limit` characters per line, so an error never echoes a huge line.
pub fn clip_lines(text: &str, limit: usize) -> String {
    let clip = |line: &str| match line.char_indices().nth(limit) {
        Some((at, _)) => format!("{}…", &line[..at]),
        None => line.to_string(),
    };
    text.lines().map(clip).collect::<Vec<_>>().join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_regular_and_oversized_files_are_refused_by_name() {
        let dir = std::env::temp_dir();
        let e = read_limited(&dir, 10, "scene file").unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let big = dir.join(format!("softshadow-big-{}.txt", std::process::id()));
        std::fs::write(&big, [b'x'; 11]).unwrap();
        let e = read_limited(&big, 10, "scene file").unwrap_err().to_string();
        assert!(e.contains("11 bytes") && e.contains("limit of 10"), "{e}");
        assert_eq!(read_limited(&big, 11, "scene file").unwrap().len(), 11);
        std::fs::remove_file(big).unwrap();
    }

    #[test]
    fn long_lines_are_found_and_clipped() {
        assert_eq!(overlong_line(b"ab\nabcdef\nx", 3), Some(2));
        assert_eq!(overlong_line(b"ab\nabc", 3), None);
        assert_eq!(clip_lines("short\nabcdefgh", 4), "shor…\nabcd…");
    }
}
