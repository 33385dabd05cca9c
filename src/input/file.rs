//! Reading input files without hanging or exhausting memory.
//!
//! Decks, topologies, force fields (and their `include`s) and restart files
//! named by `read_state` must be regular files of at most
//! [`MAX_INPUT_BYTES`]: a FIFO would block the reader forever, `/dev/zero`
//! would grow without end, and a directory cannot be read. The file type is
//! checked before the file is opened (opening a FIFO for reading blocks), and
//! the read itself stops one byte past the cap in case the file grows.

use std::io::Read;
use std::path::Path;

/// The largest input file read: 1 GiB (a topology of ~10⁷ beads).
pub const MAX_INPUT_BYTES: u64 = 1 << 30;

/// Why a path is not a readable input file, or `Ok` if it is one.
pub fn check_input_file(path: &Path) -> Result<(), String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("{e}; expected an existing, readable text file"))?;
    if !meta.is_file() {
        return Err(format!("it is {}; expected a regular file", file_kind(&meta.file_type())));
    }
    if meta.len() > MAX_INPUT_BYTES {
        return Err(too_large(meta.len()));
    }
    Ok(())
}

/// The bytes of a regular input file of at most [`MAX_INPUT_BYTES`].
pub fn read_input_file(path: &Path) -> Result<Vec<u8>, String> {
    check_input_file(path)?;
    let file = std::fs::File::open(path).map_err(|e| format!("{e}; expected an existing, readable text file"))?;
    let mut bytes = Vec::new();
    file.take(MAX_INPUT_BYTES + 1).read_to_end(&mut bytes).map_err(|e| format!("{e}; expected a readable text file"))?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

fn too_large(len: u64) -> String {
    format!("it has more than {MAX_INPUT_BYTES} bytes ({len}); expected an input file of at most 1 GiB")
}

fn file_kind(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_is_not_a_regular_file_quickly() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(read_input_file(dir.path()).unwrap_err(), "it is a directory; expected a regular file");
        #[cfg(unix)]
        {
            let started = std::time::Instant::now();
            assert_eq!(read_input_file(Path::new("/dev/zero")).unwrap_err(), "it is a device; expected a regular file");
            let fifo = dir.path().join("fifo");
            let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
            assert!(made.success());
            assert_eq!(read_input_file(&fifo).unwrap_err(), "it is a FIFO (named pipe); expected a regular file");
            assert!(started.elapsed().as_secs_f64() < 1.0);
        }
        let file = dir.path().join("ok.in");
        std::fs::write(&file, "run 1\n").unwrap();
        assert_eq!(read_input_file(&file).unwrap(), b"run 1\n");
        let huge = dir.path().join("huge.top");
        std::fs::File::create(&huge).unwrap().set_len(MAX_INPUT_BYTES + 1).unwrap();
        assert_eq!(read_input_file(&huge).unwrap_err(), too_large(MAX_INPUT_BYTES + 1));
        assert!(read_input_file(&dir.path().join("missing")).unwrap_err().contains("expected an existing, readable text file"));
    }
}
