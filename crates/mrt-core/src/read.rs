//! Reading a file whose size is known before it is read: every file MRT reads from a path a
//! user gives (configurations, behaviors, rule bases, logs, maps, recordings) goes through
//! [`read_bounded`], so that a link to `/dev/zero`, a named pipe or a file of gigabytes is
//! refused with its size and the limit instead of filling the memory.

use std::io::Read;
use std::path::Path;

/// The largest configuration file (TOML: a world, a robot, a camera, a map, a network), bytes.
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// The largest script or rule file (a Lua behavior, an HFSM, a Mr. BRIAN file), bytes.
pub const MAX_SCRIPT_BYTES: u64 = 8 << 20;

/// The largest log of readings (a mice calibration log, a frame truth), bytes.
pub const MAX_LOG_BYTES: u64 = 256 << 20;

/// The contents of the regular file `path`, if it holds at most `limit` bytes. A path that is
/// not a regular file (a directory, a device such as `/dev/zero`, a pipe; links are followed)
/// or a larger file is refused before it is read, and no more than `limit` bytes are read if
/// the file grows meanwhile. The error says which, with the size and the limit.
///
/// ```
/// let dir = std::env::temp_dir().join(format!("mrt-core-read-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let file = dir.join("a.toml");
/// std::fs::write(&file, "x = 1\n")?;
/// assert_eq!(mrt_core::read_bounded(&file, 100)?, b"x = 1\n");
/// let e = mrt_core::read_bounded(&file, 3).unwrap_err();
/// assert_eq!(e.to_string(), "is 6 bytes, more than the 3 bytes such a file may have");
/// assert!(mrt_core::read_bounded(&dir, 100).is_err(), "a directory");
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn read_bounded(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let kind = std::fs::metadata(path)?;
    if !kind.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "is not a regular file (a directory, a device or a pipe)",
        ));
    }
    let too_large = |size: u64| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("is {size} bytes, more than the {limit} bytes such a file may have"),
        )
    };
    if kind.len() > limit {
        return Err(too_large(kind.len()));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(kind.len()).unwrap_or(0));
    std::fs::File::open(path)?.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// [`read_bounded`] as UTF-8 text, a leading byte-order mark (which some editors write)
/// left out.
pub fn read_text(path: &Path, limit: u64) -> std::io::Result<String> {
    let bytes = read_bounded(path, limit)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("is not UTF-8 text (byte {at} is not part of a character)"),
        )
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_owned(),
        None => text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_a_directory_and_a_file_too_large_are_refused_before_reading() {
        if Path::new("/dev/zero").exists() {
            let e = read_bounded(Path::new("/dev/zero"), 10).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
        let dir = std::env::temp_dir().join(format!("mrt-core-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert!(read_bounded(&dir, 10).unwrap_err().to_string().contains("not a regular file"));
        let big = dir.join("big");
        std::fs::write(&big, vec![b'x'; 11]).unwrap();
        let e = read_bounded(&big, 10).unwrap_err().to_string();
        assert_eq!(e, "is 11 bytes, more than the 10 bytes such a file may have");
        assert_eq!(read_bounded(&big, 11).unwrap().len(), 11);
        std::fs::write(&big, b"\xef\xbb\xbfname = 1\n").unwrap();
        assert_eq!(read_text(&big, 100).unwrap(), "name = 1\n", "the BOM left out");
        std::fs::write(&big, b"ok\xff").unwrap();
        let e = read_text(&big, 100).unwrap_err().to_string();
        assert!(e.contains("not UTF-8") && e.contains("byte 2"), "{e}");
        assert!(read_bounded(&dir.join("absent"), 10).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
