//! Output files written in whole records, so that a kill or a full disk
//! never leaves a partial frame or row behind.
//!
//! A writer assembles each record (a trajectory frame, a thermo row, the
//! event rows of a step, an MCAP chunk) in memory and hands it over with
//! [`RecordFile::commit`], which writes everything pending with one
//! `write` and only then counts it as on disk. What the kernel holds
//! survives a SIGKILL of the process (not a power cut: that is what the
//! synced restarts are for). When a write fails — `ENOSPC`, `EFBIG`, an I/O
//! error — the bytes it managed to put down are cut off again (`ftruncate`
//! to the end of the last whole record), so the file stays a clean prefix
//! of whole records and the error goes to the run, which stops with
//! `OUTPUT_ERROR_STATUS`.
//!
//! A record is only lost to a SIGKILL if the kill lands before it is
//! committed, or inside the `write` of it (the kernel may then keep part
//! of it: a window of microseconds per record).

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};
use std::time::{Duration, Instant};

/// How long complete records may wait in memory when a writer batches them
/// ([`RecordFile::commit_batched`]): the event log's rows, and an MCAP's
/// messages between frames.
pub const BATCH_INTERVAL: Duration = Duration::from_secs(1);
/// How many bytes may wait in memory before a batch is written regardless.
pub const BATCH_BYTES: usize = 1 << 16;

/// A file of whole records (see the module docs). Bytes written through
/// [`Write`] are pending until [`commit`](Self::commit); `flush` commits.
pub struct RecordFile {
    file: File,
    pending: Vec<u8>,
    /// Length of the file up to its last whole record.
    committed: u64,
    last_commit: Instant,
}

impl RecordFile {
    /// A record file over `file`, which must be empty (as opened for output).
    pub fn new(file: File) -> Self {
        Self { file, pending: Vec::new(), committed: 0, last_commit: Instant::now() }
    }

    /// Writes every pending byte (whole records) with one write; on failure
    /// the file is cut back to its last whole record.
    pub fn commit(&mut self) -> io::Result<()> {
        if !self.pending.is_empty() {
            if let Err(e) = self.file.write_all(&self.pending) {
                // Whatever part of the write got through is cut off again.
                let _ = self.file.set_len(self.committed);
                let _ = self.file.seek(SeekFrom::Start(self.committed));
                return Err(e);
            }
            self.committed += self.pending.len() as u64;
            self.pending.clear();
        }
        self.last_commit = Instant::now();
        Ok(())
    }

    /// Commits when records have waited [`BATCH_INTERVAL`] or fill
    /// [`BATCH_BYTES`]; call it at record boundaries only.
    pub fn commit_batched(&mut self) -> io::Result<()> {
        if self.pending.len() >= BATCH_BYTES || self.last_commit.elapsed() >= BATCH_INTERVAL {
            self.commit()
        } else {
            Ok(())
        }
    }

    /// Overwrites bytes already on disk (a header's counters); `offset..offset
    /// + bytes.len()` must lie within the whole records.
    pub fn overwrite(&mut self, offset: u64, bytes: &[u8]) -> io::Result<()> {
        if offset + bytes.len() as u64 > self.committed {
            return Err(io::Error::other("overwriting past the last whole record"));
        }
        #[cfg(unix)]
        {
            use std::os::unix::fs::FileExt;
            self.file.write_all_at(bytes, offset)
        }
        #[cfg(not(unix))]
        {
            self.file.seek(SeekFrom::Start(offset))?;
            self.file.write_all(bytes)?;
            self.file.seek(SeekFrom::Start(self.committed)).map(|_| ())
        }
    }

    /// Commits what is pending and syncs the file to disk.
    pub fn finish(&mut self) -> io::Result<()> {
        self.commit()?;
        self.file.sync_data()
    }
}

impl Write for RecordFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.pending.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.pending.extend_from_slice(buf);
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        self.commit()
    }
}

/// Position queries only (the MCAP writer asks where it stands): a record
/// file is written in order and never seeks.
impl Seek for RecordFile {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        let here = self.committed + self.pending.len() as u64;
        match pos {
            SeekFrom::Current(0) | SeekFrom::End(0) => Ok(here),
            SeekFrom::Start(p) if p == here => Ok(here),
            _ => Err(io::Error::new(io::ErrorKind::Unsupported, "a record file is written in order")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_reach_the_file_whole_when_committed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.txt");
        let mut r = RecordFile::new(File::create(&path).unwrap());
        writeln!(r, "one").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"");
        r.commit().unwrap();
        writeln!(r, "two").unwrap();
        assert_eq!(r.stream_position().unwrap(), 8);
        r.commit_batched().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "one\n", "a batch waits up to its interval");
        r.overwrite(0, b"ONE").unwrap();
        assert!(r.overwrite(2, b"xx\nyy").is_err());
        assert!(r.seek(SeekFrom::Start(0)).is_err());
        r.finish().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "ONE\ntwo\n");
    }
}
