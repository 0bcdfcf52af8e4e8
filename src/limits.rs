//! What input may make candela read or allocate: the memory this process may still use, and
//! file reads that refuse what is not a regular file (a FIFO would block forever, `/dev/zero`
//! never ends) or is larger than a limit, before a byte is read.
//!
//! Every allocation whose size comes from input (a film, a heat map, a decoded EXR, a mesh, a
//! benchmark's rays) is checked here first with [`check_memory`], so an absurd size ends in an
//! error naming what asked for it and the limit, not in the allocator's abort.

use std::io::Read;
use std::path::Path;

/// One gibibyte in bytes, for messages.
pub const GIB: f64 = (1u64 << 30) as f64;

/// Largest text description (scene RON, spectrum CSV, IES/LDT photometry) read, in bytes.
pub const MAX_TEXT_BYTES: u64 = 256 << 20;

/// Memory a command holds before it reads its inputs (the program, its libraries, the
/// allocator's and the threads' first pages), added to the estimates of what it reads: about
/// 20 MB measured.
pub const BASE_BYTES: u64 = 32 << 20;

/// Memory this process may still allocate in bytes (Linux: `MemAvailable`, the cgroup v2
/// limit and the address-space limit `ulimit -v`), or `None` where the system does not say.
pub fn available_memory_bytes() -> Option<u64> {
    available_memory().map(|(bytes, _)| bytes)
}

/// [`available_memory_bytes`] and, when the address-space limit is what bounds it, a note
/// saying so for messages.
fn available_memory() -> Option<(u64, &'static str)> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb: u64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    let mut avail = kb.saturating_mul(1024);
    let cg = |f: &str| -> Option<u64> { std::fs::read_to_string(f).ok()?.trim().parse().ok() };
    if let (Some(max), Some(cur)) = (
        cg("/sys/fs/cgroup/memory.max"),
        cg("/sys/fs/cgroup/memory.current"),
    ) {
        avail = avail.min(max.saturating_sub(cur));
    }
    if let Some(space) = address_space_left().filter(|&s| s < avail) {
        return Some((space, " under the address-space limit (ulimit -v)"));
    }
    Some((avail, ""))
}

/// What `ulimit -v` (RLIMIT_AS) still leaves: the limit less the process's current virtual
/// size (`VmSize`) and the reserves of [`address_space_margin`]; `None` without a limit.
/// Under such a limit an allocation beyond it fails (and Rust aborts), however much memory
/// the machine has free.
pub fn address_space_left() -> Option<u64> {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: getrlimit only writes the struct it is given.
        let mut lim: libc::rlimit = unsafe { std::mem::zeroed() };
        if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) } != 0
            || lim.rlim_cur == libc::RLIM_INFINITY
        {
            return None;
        }
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let kb: u64 = status
            .lines()
            .find_map(|l| l.strip_prefix("VmSize:"))?
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()?;
        #[allow(clippy::unnecessary_cast)] // rlim_t is u64 on Linux, but not everywhere
        let limit = lim.rlim_cur as u64;
        Some(
            limit
                .saturating_sub(kb.saturating_mul(1024))
                .saturating_sub(address_space_margin()),
        )
    }
    #[cfg(not(target_os = "linux"))]
    {
        None
    }
}

/// Address space that threads still to start reserve beyond any allocation: the stacks and
/// glibc's malloc arenas (64 MiB of address space each, made as threads first allocate; a
/// render on 2 cores maps about 400 MiB more than it touches, measured as `VmPeak` − `VmHWM`).
/// 64 MiB plus 192 MiB per core.
pub fn address_space_margin() -> u64 {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
    (64 << 20) + cores * (192 << 20)
}

/// Refuse `need_bytes` for `what` (e.g. "the heat map of grid \"desk\"") when it exceeds the
/// memory available; the message names both sizes. Where the system does not say how much is
/// available, only sizes beyond the address space (2⁴⁸ bytes) are refused.
pub fn check_memory(need_bytes: u64, what: &str) -> Result<(), String> {
    const ADDRESS_SPACE: u64 = 1 << 48;
    let (limit, note) = available_memory().unwrap_or((ADDRESS_SPACE, ""));
    if need_bytes > limit {
        return Err(format!(
            "{what} needs about {:.1} GiB of memory but only {:.1} GiB is available{note}",
            need_bytes as f64 / GIB,
            limit as f64 / GIB
        ));
    }
    Ok(())
}

/// Read a whole file of at most `max_bytes` (and within the memory available). A FIFO, a
/// device or a directory is refused without being opened (opening a FIFO blocks until a writer
/// comes; `/dev/zero` never ends); a file that grows past the limit while being read is refused
/// too. Errors are `io::Error`s whose message says what was wrong, for the caller to put beside
/// the path.
pub fn read_file(path: &Path, max_bytes: u64) -> std::io::Result<Vec<u8>> {
    use std::io::{Error, ErrorKind};
    let meta = std::fs::metadata(path)?;
    let ft = meta.file_type();
    if !ft.is_file() {
        let kind = if ft.is_dir() {
            "a directory"
        } else if is_fifo(&ft) {
            "a FIFO (named pipe)"
        } else {
            "a device or special file"
        };
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("is {kind}, not a regular file"),
        ));
    }
    let too_large = |len: u64| {
        Error::new(
            ErrorKind::InvalidInput,
            format!(
                "is {} bytes, more than the limit of {} bytes for this kind of file",
                len, max_bytes
            ),
        )
    };
    if meta.len() > max_bytes {
        return Err(too_large(meta.len()));
    }
    check_memory(meta.len(), "reading the file")
        .map_err(|m| Error::new(ErrorKind::OutOfMemory, m))?;
    let file = std::fs::File::open(path)?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max_bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// [`read_file`] as UTF-8 text; a byte-order mark at the start is dropped.
pub fn read_text(path: &Path, max_bytes: u64) -> std::io::Result<String> {
    let bytes = read_file(path, max_bytes)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "is not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

#[cfg(unix)]
fn is_fifo(ft: &std::fs::FileType) -> bool {
    use std::os::unix::fs::FileTypeExt;
    ft.is_fifo()
}

#[cfg(not(unix))]
fn is_fifo(_ft: &std::fs::FileType) -> bool {
    false
}

/// Input text made safe to print inside a message: control characters (CR, NUL, escape
/// sequences) are shown as `\u{..}` escapes and the text is cut at `max_chars` characters.
pub fn printable(text: &str, max_chars: usize) -> String {
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == max_chars {
            out.push('…');
            break;
        }
        if c.is_control() && c != '\t' {
            out.push_str(&c.escape_unicode().to_string());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_special_files_and_large_ones() {
        let e = read_file(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let e = read_file(dir.path(), 1 << 20).unwrap_err();
        assert!(e.to_string().contains("directory"), "{e}");
        let f = dir.path().join("big.txt");
        std::fs::write(&f, vec![b'a'; 2000]).unwrap();
        let e = read_file(&f, 1000).unwrap_err();
        assert!(e.to_string().contains("2000 bytes"), "{e}");
        assert_eq!(read_file(&f, 2000).unwrap().len(), 2000);
    }

    #[cfg(unix)]
    #[test]
    fn refuses_a_fifo_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("pipe");
        let st = std::process::Command::new("mkfifo")
            .arg(&f)
            .status()
            .unwrap();
        assert!(st.success());
        let e = read_file(&f, 1 << 20).unwrap_err();
        assert!(e.to_string().contains("FIFO"), "{e}");
    }

    #[test]
    fn text_drops_a_bom_and_refuses_non_utf8() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("t.txt");
        std::fs::write(&f, b"\xEF\xBB\xBFv 0 0 0\n").unwrap();
        assert_eq!(read_text(&f, 100).unwrap(), "v 0 0 0\n");
        std::fs::write(&f, b"ab\xFFcd").unwrap();
        let e = read_text(&f, 100).unwrap_err();
        assert!(e.to_string().contains("offset 2"), "{e}");
    }

    #[test]
    fn memory_check_names_what_and_sizes() {
        let e = check_memory(u64::MAX, "the heat map").unwrap_err();
        assert!(e.starts_with("the heat map needs about"), "{e}");
        assert!(check_memory(1024, "a small thing").is_ok());
    }

    #[test]
    fn printable_escapes_control_characters() {
        assert_eq!(printable("a\rb\0c", 100), "a\\u{d}b\\u{0}c");
        assert_eq!(printable("abcdef", 3), "abc…");
    }
}
