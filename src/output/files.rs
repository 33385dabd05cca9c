//! Opening output files: inside the output directory (`cellmd run -o DIR`)
//! no symbolic link is ever followed.
//!
//! A deck's output paths are relative to the output directory, and the deck
//! validator refuses absolute paths and `..` (unless `--allow-outside`).
//! What it cannot see is the directory's contents when the run starts: a
//! `traj.xyz`, a `deck.log`, a `sub/` or a stale `s.restart.tmp` planted there
//! as a link would send the output elsewhere. So every output beneath the
//! output directory is opened component by component from a descriptor of
//! that directory (`openat`): each subdirectory with `O_NOFOLLOW |
//! O_DIRECTORY`, the file itself with `O_NOFOLLOW`, and the file must then be
//! a regular file with no other hard link (a FIFO would block the run, and
//! truncating a hard link would empty its other name too). Only then is it
//! truncated. A link is refused with an error naming it; nothing is written
//! through it. The output directory itself may be a link (the user named
//! it), and paths outside it (`--allow-outside`) are opened as given.
//!
//! Whole-file outputs (restarts, the lifetime table) are written to
//! `NAME.tmp` beside `NAME` — a stale `NAME.tmp`, link or not, is removed
//! first and the new one created exclusively — synced, and renamed over
//! `NAME` (`renameat`, which replaces a name and never follows it), so a
//! reader or a kill sees the old file or the new one, never a mix.

use std::fs::{self, File};
use std::io::{self, BufWriter};
use std::path::{Component, Path, PathBuf};

/// The part of `path` beneath `root`, if `path` lies there (no `..`).
fn beneath<'a>(root: &Path, path: &'a Path) -> Option<&'a Path> {
    let rest = path.strip_prefix(root).ok()?;
    rest.components().all(|c| matches!(c, Component::Normal(_) | Component::CurDir)).then_some(rest)
}

/// Creates (or truncates) the output file `path`; below `root` no link is
/// followed (see the module docs).
pub fn create(root: &Path, path: &Path) -> io::Result<File> {
    match beneath(root, path) {
        Some(rest) => confined::create(root, rest),
        None => File::create(path),
    }
}

/// Writes `path` through `fill` atomically (via `path.tmp` and a rename); on
/// error the temporary file is removed and `path` is left as it was.
pub fn write_atomically(root: &Path, path: &Path, fill: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) -> io::Result<()> {
    match beneath(root, path) {
        Some(rest) => confined::write_atomically(root, rest, fill),
        None => plain_write_atomically(path, fill),
    }
}

/// Writes each `(name, text)` of `files` into `dir` (created if needed),
/// one after the other and each atomically (see [`write_atomically`], with
/// `dir` as the root beneath which no link is followed): a kill or a full
/// disk leaves every name with its old contents or its new ones, never part
/// of a file. A file that names the others should come last. The error
/// names the file that could not be written.
pub fn write_all_atomically(dir: &Path, files: &[(&str, &str)]) -> io::Result<()> {
    use std::io::Write;
    let named = |path: &Path, e: io::Error| io::Error::new(e.kind(), format!("{}: {e}", path.display()));
    fs::create_dir_all(dir).map_err(|e| named(dir, e))?;
    for (name, text) in files {
        let path = dir.join(name);
        write_atomically(dir, &path, |out| out.write_all(text.as_bytes())).map_err(|e| named(&path, e))?;
    }
    Ok(())
}

/// Removes the output file `path` (an old checkpoint); below `root` through
/// no link.
pub fn remove(root: &Path, path: &Path) -> io::Result<()> {
    match beneath(root, path) {
        Some(rest) => confined::remove(root, rest),
        None => fs::remove_file(path),
    }
}

/// The temporary file beside `path` that an atomic write goes through.
pub fn tmp_path(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".tmp");
    PathBuf::from(name)
}

fn plain_write_atomically(path: &Path, fill: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) -> io::Result<()> {
    let tmp = tmp_path(path);
    let result = (|| -> io::Result<()> {
        let mut out = BufWriter::new(File::create(&tmp)?);
        fill(&mut out)?;
        let file = out.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        fs::rename(&tmp, path)?;
        // Persist the rename itself where the platform allows opening a directory.
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            if let Ok(dir) = File::open(dir) {
                let _ = dir.sync_all();
            }
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

#[cfg(unix)]
mod confined {
    //! The `openat` walk beneath the output directory.
    use std::ffi::{CString, OsStr};
    use std::fs::File;
    use std::io::{self, BufWriter, Write};
    use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
    use std::os::unix::ffi::OsStrExt;
    use std::path::{Component, Path};

    fn c_name(name: &OsStr) -> io::Result<CString> {
        CString::new(name.as_bytes()).map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "a file name with a NUL byte"))
    }

    fn last_error() -> io::Error {
        io::Error::last_os_error()
    }

    /// `what` refused because it is a link or not what an output needs.
    fn refused(what: &Path, why: &str) -> io::Error {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("`{}` {why}; cellmd writes no output through links inside the output directory", what.display()),
        )
    }

    /// The directory holding the last component of `rest`, opened from
    /// `root` without following a link, and that component's name.
    fn parent(root: &Path, rest: &Path) -> io::Result<(OwnedFd, CString)> {
        let names: Vec<&OsStr> = rest.components().filter_map(|c| if let Component::Normal(n) = c { Some(n) } else { None }).collect();
        let Some((last, dirs)) = names.split_last() else {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, "an output path names no file"));
        };
        let root_name = c_name(if root.as_os_str().is_empty() { OsStr::new(".") } else { root.as_os_str() })?;
        // SAFETY: a NUL-terminated path; the descriptor is owned below.
        let fd = unsafe { libc::open(root_name.as_ptr(), libc::O_RDONLY | libc::O_DIRECTORY | libc::O_CLOEXEC) };
        if fd < 0 {
            return Err(last_error());
        }
        // SAFETY: `fd` was just opened and is owned by nobody else.
        let mut dir = unsafe { OwnedFd::from_raw_fd(fd) };
        let mut walked = root.to_path_buf();
        for name in dirs {
            walked.push(name);
            let c = c_name(name)?;
            // SAFETY: `dir` is an open directory and `c` NUL-terminated.
            let fd = unsafe {
                libc::openat(dir.as_raw_fd(), c.as_ptr(), libc::O_RDONLY | libc::O_DIRECTORY | libc::O_NOFOLLOW | libc::O_CLOEXEC)
            };
            if fd < 0 {
                let e = last_error();
                return Err(match e.raw_os_error() {
                    Some(libc::ELOOP) | Some(libc::ENOTDIR) => refused(&walked, "is a symbolic link or not a directory"),
                    _ => e,
                });
            }
            // SAFETY: as above.
            dir = unsafe { OwnedFd::from_raw_fd(fd) };
        }
        Ok((dir, c_name(last)?))
    }

    /// `fstat` of an open file.
    fn stat(fd: &impl AsRawFd) -> io::Result<libc::stat> {
        // SAFETY: `st` is written by fstat before it is read.
        let mut st: libc::stat = unsafe { std::mem::zeroed() };
        if unsafe { libc::fstat(fd.as_raw_fd(), &mut st) } != 0 {
            return Err(last_error());
        }
        Ok(st)
    }

    pub fn create(root: &Path, rest: &Path) -> io::Result<File> {
        let shown = root.join(rest);
        let (dir, name) = parent(root, rest)?;
        // Non-blocking, so a FIFO without a reader fails at once instead of blocking the open.
        let flags = libc::O_WRONLY | libc::O_CREAT | libc::O_NOFOLLOW | libc::O_CLOEXEC | libc::O_NONBLOCK;
        // SAFETY: `dir` is an open directory and `name` NUL-terminated.
        let fd = unsafe { libc::openat(dir.as_raw_fd(), name.as_ptr(), flags, 0o666 as libc::c_uint) };
        if fd < 0 {
            let e = last_error();
            return Err(match e.raw_os_error() {
                Some(libc::ELOOP) => refused(&shown, "is a symbolic link"),
                Some(libc::ENXIO) => refused(&shown, "is a FIFO or socket"),
                _ => e,
            });
        }
        // SAFETY: `fd` was just opened and is owned by nobody else.
        let file = unsafe { File::from_raw_fd(fd) };
        let st = stat(&file)?;
        if st.st_mode & libc::S_IFMT != libc::S_IFREG {
            return Err(refused(&shown, "is not a regular file"));
        }
        if st.st_nlink > 1 {
            return Err(refused(&shown, "has another hard link"));
        }
        // SAFETY: clearing O_NONBLOCK on our own descriptor.
        if unsafe { libc::fcntl(file.as_raw_fd(), libc::F_SETFL, 0) } != 0 {
            return Err(last_error());
        }
        file.set_len(0)?;
        Ok(file)
    }

    /// Unlinks `name` in `dir`; a missing name is no error.
    fn unlink(dir: &OwnedFd, name: &CString) -> io::Result<()> {
        // SAFETY: `dir` is an open directory and `name` NUL-terminated.
        if unsafe { libc::unlinkat(dir.as_raw_fd(), name.as_ptr(), 0) } != 0 {
            let e = last_error();
            if e.kind() != io::ErrorKind::NotFound {
                return Err(e);
            }
        }
        Ok(())
    }

    pub fn write_atomically(root: &Path, rest: &Path, fill: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) -> io::Result<()> {
        let shown = root.join(rest);
        let (dir, name) = parent(root, rest)?;
        // The file it replaces must be a regular file (or absent), never a link.
        // SAFETY: `st` is written by fstatat before it is read.
        let mut st: libc::stat = unsafe { std::mem::zeroed() };
        if unsafe { libc::fstatat(dir.as_raw_fd(), name.as_ptr(), &mut st, libc::AT_SYMLINK_NOFOLLOW) } == 0 {
            if st.st_mode & libc::S_IFMT == libc::S_IFLNK {
                return Err(refused(&shown, "is a symbolic link"));
            }
            if st.st_mode & libc::S_IFMT != libc::S_IFREG {
                return Err(refused(&shown, "is not a regular file"));
            }
        }
        let mut tmp_bytes = name.as_bytes().to_vec();
        tmp_bytes.extend_from_slice(b".tmp");
        let tmp = CString::new(tmp_bytes).expect("no NUL was in the name");
        // A stale temporary (an interrupted write, or a planted link) goes first.
        unlink(&dir, &tmp)?;
        let flags = libc::O_WRONLY | libc::O_CREAT | libc::O_EXCL | libc::O_NOFOLLOW | libc::O_CLOEXEC;
        // SAFETY: as in `create`.
        let fd = unsafe { libc::openat(dir.as_raw_fd(), tmp.as_ptr(), flags, 0o666 as libc::c_uint) };
        if fd < 0 {
            return Err(last_error());
        }
        // SAFETY: `fd` was just opened and is owned by nobody else.
        let file = unsafe { File::from_raw_fd(fd) };
        let result = (|| -> io::Result<()> {
            let mut out = BufWriter::new(file);
            fill(&mut out)?;
            out.flush()?;
            let file = out.into_inner().map_err(|e| e.into_error())?;
            file.sync_all()?;
            drop(file);
            // SAFETY: both names NUL-terminated, in the open directory `dir`.
            if unsafe { libc::renameat(dir.as_raw_fd(), tmp.as_ptr(), dir.as_raw_fd(), name.as_ptr()) } != 0 {
                return Err(last_error());
            }
            // Persist the rename itself.
            // SAFETY: syncing our own directory descriptor.
            unsafe { libc::fsync(dir.as_raw_fd()) };
            Ok(())
        })();
        if result.is_err() {
            let _ = unlink(&dir, &tmp);
        }
        result
    }

    pub fn remove(root: &Path, rest: &Path) -> io::Result<()> {
        let (dir, name) = parent(root, rest)?;
        // SAFETY: `dir` is an open directory and `name` NUL-terminated.
        if unsafe { libc::unlinkat(dir.as_raw_fd(), name.as_ptr(), 0) } != 0 {
            return Err(last_error());
        }
        Ok(())
    }
}

#[cfg(not(unix))]
mod confined {
    //! Without `openat`: the paths as given.
    use std::fs::File;
    use std::io::{self, BufWriter};
    use std::path::Path;

    pub fn create(root: &Path, rest: &Path) -> io::Result<File> {
        File::create(root.join(rest))
    }

    pub fn write_atomically(root: &Path, rest: &Path, fill: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) -> io::Result<()> {
        super::plain_write_atomically(&root.join(rest), fill)
    }

    pub fn remove(root: &Path, rest: &Path) -> io::Result<()> {
        std::fs::remove_file(root.join(rest))
    }
}

#[cfg(all(test, unix))]
mod tests {
    use std::io::Write;
    use std::os::unix::fs::symlink;

    use super::*;

    #[test]
    fn links_beneath_the_root_are_refused_and_nothing_is_written_through_them() {
        let root = tempfile::tempdir().unwrap();
        let outside = tempfile::tempdir().unwrap();
        let r = root.path();
        let target = outside.path().join("victim");
        fs::write(&target, "keep").unwrap();
        symlink(&target, r.join("t.xyz")).unwrap();
        symlink(outside.path(), r.join("sub")).unwrap();
        symlink(&target, r.join("s.restart.tmp")).unwrap();
        fs::hard_link(&target, r.join("hard.csv")).unwrap();
        let err = create(r, &r.join("t.xyz")).unwrap_err().to_string();
        assert!(err.contains("t.xyz` is a symbolic link; cellmd writes no output through links"), "{err}");
        let err = create(r, &r.join("sub/t.xyz")).unwrap_err().to_string();
        assert!(err.contains("sub` is a symbolic link or not a directory"), "{err}");
        let err = create(r, &r.join("hard.csv")).unwrap_err().to_string();
        assert!(err.contains("has another hard link"), "{err}");
        assert!(write_atomically(r, &r.join("sub/s.restart"), |o| o.write_all(b"x")).is_err());
        assert!(write_atomically(r, &r.join("t.xyz"), |o| o.write_all(b"x")).unwrap_err().to_string().contains("symbolic link"));
        // A planted temporary is replaced (the link itself removed), not written through.
        write_atomically(r, &r.join("s.restart"), |o| o.write_all(b"state")).unwrap();
        assert_eq!(fs::read_to_string(r.join("s.restart")).unwrap(), "state");
        assert!(!r.join("s.restart.tmp").exists());
        assert!(remove(r, &r.join("sub/victim")).is_err());
        assert_eq!(fs::read_to_string(&target).unwrap(), "keep");
        assert_eq!(fs::read_dir(outside.path()).unwrap().count(), 1);
    }

    #[test]
    fn regular_files_and_real_subdirectories_are_written() {
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        fs::create_dir(r.join("sub")).unwrap();
        fs::write(r.join("sub/t.csv"), "old contents").unwrap();
        let mut f = create(r, &r.join("sub/t.csv")).unwrap();
        f.write_all(b"new").unwrap();
        assert_eq!(fs::read_to_string(r.join("sub/t.csv")).unwrap(), "new");
        // The root itself may be a link, and `.` as root takes relative paths.
        let link = tempfile::tempdir().unwrap();
        symlink(r, link.path().join("out")).unwrap();
        create(&link.path().join("out"), &link.path().join("out/a.csv")).unwrap();
        assert!(r.join("a.csv").exists());
        assert_eq!(beneath(Path::new("."), Path::new("./x/y.csv")), Some(Path::new("x/y.csv")));
        assert_eq!(beneath(Path::new("out"), Path::new("out/../y.csv")), None);
        remove(r, &r.join("a.csv")).unwrap();
        assert!(!r.join("a.csv").exists());
    }

    #[test]
    fn a_fifo_is_refused_at_once() {
        let root = tempfile::tempdir().unwrap();
        let fifo = root.path().join("t.xyz");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let err = create(root.path(), &fifo).unwrap_err().to_string();
        assert!(err.contains("is a FIFO or socket"), "{err}");
    }
}
