//! Input limits: the one policy on how much an input may make asperity allocate.
//!
//! A grid is at most [`Limits::max_points`] points ([`DEFAULT_MAX_POINTS`] = 2^28, a
//! 16384 × 16384 map, unless raised with `--max-points` or the study's `[limits] max_points`),
//! whatever declares it: a file's header, a synthetic surface, a resampling or the study's
//! `[contact] grid`. Input files are read only when they are regular files (not a directory,
//! device or pipe), and never past [`Limits::max_file_bytes`], the most a file within the point
//! limit can need; a file's own header is checked against the bytes it actually holds before
//! anything is allocated from it (see the readers).
//!
//! Within the point limit, a grid may still need more memory than the machine has: each gate
//! that knows a grid (reading, generating, resampling, a contact solve, a study's preparation)
//! estimates the bytes it needs and refuses in one line, naming the estimate, when they exceed
//! [`available_memory`]; the largest arrays are reserved fallibly ([`zeroed`]), so that an
//! allocation failing despite the estimate is an error too, not an abort.
//!
//! The worker threads are bounded too ([`start_threads`]): at most [`MAX_THREADS`], and
//! [`THREADS_PER_CORE`] per available core.
//!
//! Imports only `error` and `quantity`; must not import topography, contact, friction, study,
//! report, plot, shs, cli.

use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// The default largest grid \[points]: 2^28.
pub const DEFAULT_MAX_POINTS: usize = 1 << 28;

/// The most bytes any format needs per point: a line of text holding x, y and z at full
/// precision (about 75 bytes), or the float64 heights of 16 channels of a binary file.
pub const BYTES_PER_POINT: u64 = 128;

/// Room for a file's headers, metadata and a study's text, beyond its points [bytes].
const HEADER_BYTES: u64 = 16 << 20;

/// The largest length a file can have (a file offset is signed, 63 bits) [bytes]: the byte caps
/// saturate here, so that one past a cap never wraps, whatever the point limit.
const LARGEST_FILE_BYTES: u64 = i64::MAX as u64;

/// Bytes per point at the peak of a contact solve on a periodic grid (heights, pressure,
/// displacement, gaps, the contact set and the FFT's spectra); a free boundary solves on a
/// grid padded to 2nx × 2ny.
pub const CONTACT_BYTES_PER_POINT: u64 = 57;

/// Bytes per point of the window at the peak of a tangential solve's setup (a sliding onset's,
/// a stuck contact's stiffness) on a contact spread over a periodic window: the operator on the
/// window and its responses, its offsets, single-precision copy and preconditioner, the
/// contact points' vectors; a free boundary pads the contact's box to 2bx × 2by. Measured at
/// 2048², 1 mN on a rough flat: 599 MB resident, 244 MB of them the normal solve's (85 bytes a
/// point beyond it; the rest is room for the transients of the operator's setup).
pub const TANGENTIAL_BYTES_PER_POINT: u64 = 128;

/// Bytes per point of generating a synthetic surface (its spectrum, FFT work, the heights and
/// a cap's).
pub const GENERATE_BYTES_PER_POINT: u64 = 40;

/// Bytes per point of the resampled grid (the heights, and the pass along x before y).
pub const RESAMPLE_BYTES_PER_POINT: u64 = 16;

/// The most worker threads asperity runs (`RAYON_NUM_THREADS`, `asperity slurm --cpus`).
pub const MAX_THREADS: usize = 4096;

/// The most worker threads per available core: more only share the same cores.
pub const THREADS_PER_CORE: usize = 64;

/// The environment variable that sets the number of worker threads (rayon's).
const THREADS_VARIABLE: &str = "RAYON_NUM_THREADS";

/// Start the global pool of worker threads once per process, as many as `RAYON_NUM_THREADS`
/// says (unset or 0: one per available core); the number started. A value that is not a count,
/// or above [`MAX_THREADS`] or [`THREADS_PER_CORE`] per available core, is refused in one line
/// naming the variable, and threads the system will not start are an error, not a panic.
pub fn start_threads() -> Result<usize> {
    static STARTED: std::sync::OnceLock<std::result::Result<usize, String>> = std::sync::OnceLock::new();
    let started = STARTED.get_or_init(|| {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let threads = threads_asked(std::env::var_os(THREADS_VARIABLE).as_deref(), cores)?;
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .map(|()| threads)
            .map_err(|e| format!("{threads} worker threads could not be started: {e}"))
    });
    started.clone().map_err(|reason| Error::invalid(THREADS_VARIABLE, reason))
}

/// The number of threads `value` (of `RAYON_NUM_THREADS`) asks for on `cores` available cores.
fn threads_asked(value: Option<&std::ffi::OsStr>, cores: usize) -> std::result::Result<usize, String> {
    let Some(value) = value else { return Ok(cores) };
    let text = value.to_string_lossy();
    let n = text.trim().parse::<usize>().map_err(|_| {
        format!("{} is not a number of threads (leave it unset for one per core)", crate::quantity::quoted(&text))
    })?;
    let most = MAX_THREADS.min(THREADS_PER_CORE.saturating_mul(cores));
    match n {
        0 => Ok(cores),
        n if n > most => Err(format!(
            "{n} threads is more than the {most} asperity runs on {cores} available cores (at most \
             {THREADS_PER_CORE} a core and {MAX_THREADS} in all)"
        )),
        n => Ok(n),
    }
}

/// How large an input may be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// The largest grid accepted \[points].
    pub max_points: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits { max_points: DEFAULT_MAX_POINTS }
    }
}

impl Limits {
    /// The limits with `max_points` as the largest grid; `option` names where it was given.
    pub fn new(max_points: usize, option: &str) -> Result<Limits> {
        if max_points < 4 {
            return Err(Error::invalid(option, format!("{max_points} points is below the smallest grid, 2 × 2")));
        }
        Ok(Limits { max_points })
    }

    /// Whether an `nx` × `ny` grid is within the limit; the reason when it is not.
    pub fn check_grid(&self, nx: usize, ny: usize) -> std::result::Result<(), String> {
        match nx.checked_mul(ny) {
            Some(n) if n <= self.max_points => Ok(()),
            n => Err(format!(
                "a {nx} × {ny} grid ({}) is over the limit of {} points (raise it with --max-points, or \
                 max_points in the study's [limits])",
                n.map_or("more points than can be counted".to_string(), |n| format!("{n} points")),
                self.max_points
            )),
        }
    }

    /// The most bytes an input file may hold: what a file within the point limit can need, at
    /// most `LARGEST_FILE_BYTES` however large the limit.
    pub fn max_file_bytes(&self) -> u64 {
        (self.max_points as u64).saturating_mul(BYTES_PER_POINT).saturating_add(HEADER_BYTES).min(LARGEST_FILE_BYTES)
    }

    /// The content of the regular file at `path`, refusing anything else (a directory, device
    /// or pipe) and any file longer than [`Limits::max_file_bytes`].
    pub fn read_file(&self, path: &Path) -> Result<Vec<u8>> {
        let cap = self.max_file_bytes();
        let mut file = open_regular(path)?;
        let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        let too_long = |len: u64| {
            Error::file(
                path,
                format!(
                    "{len} bytes is more than the {cap} bytes an input within the limit of {} points can need \
                     (raise it with --max-points)",
                    self.max_points
                ),
            )
        };
        if len > cap {
            return Err(too_long(len));
        }
        // The bytes, then their values: as many float64 bytes again for float64 data.
        check_memory(len.saturating_mul(2), &format!("reading {len} bytes and decoding them"))
            .map_err(|reason| Error::file(path, reason))?;
        // The length is checked, but a file may grow while it is read: read one byte past it.
        let mut bytes = Vec::new();
        reserve(&mut bytes, len as usize, "its bytes").map_err(|reason| Error::file(path, reason))?;
        (&mut file).take(cap.saturating_add(1)).read_to_end(&mut bytes).map_err(|e| Error::io(path, e))?;
        if bytes.len() as u64 > cap {
            return Err(too_long(bytes.len() as u64));
        }
        Ok(bytes)
    }

    /// The content of the regular file at `path` as UTF-8 text (see [`Limits::read_file`]).
    pub fn read_text(&self, path: &Path) -> Result<String> {
        String::from_utf8(self.read_file(path)?).map_err(|e| {
            Error::file(path, format!("not UTF-8 text (invalid byte at offset {})", e.utf8_error().valid_up_to()))
        })
    }
}

/// The memory this process may still allocate \[bytes]: the smallest of what the system has
/// available (`MemAvailable` of /proc/meminfo), what the memory limit of its control groups
/// leaves (a container's, a batch job's: `cgroup_left`) and what the address-space and data
/// limits (`ulimit -v`, RLIMIT_AS; RLIMIT_DATA) leave beyond what the process already maps;
/// `None` when none is known.
pub fn available_memory() -> Option<u64> {
    let kib = |text: &str, key: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        Some(line[key.len()..].trim().trim_end_matches("kB").trim().parse::<u64>().ok()? * 1024)
    };
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
    let status = std::fs::read_to_string("/proc/self/status").ok();
    let used = |key: &str| status.as_deref().and_then(|s| kib(s, key)).unwrap_or(0);
    let left = |resource, used: u64| {
        let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
        // SAFETY: getrlimit writes the struct it is given and nothing else.
        let known = unsafe { libc::getrlimit(resource, &mut limit) } == 0 && limit.rlim_cur != libc::RLIM_INFINITY;
        known.then(|| limit.rlim_cur.saturating_sub(used))
    };
    [
        meminfo.as_deref().and_then(|m| kib(m, "MemAvailable:")),
        std::fs::read_to_string("/proc/self/cgroup")
            .ok()
            .and_then(|groups| cgroup_left(Path::new("/sys/fs/cgroup"), &groups)),
        // An address-space limit counts what malloc reserves, not what it uses: per-thread
        // arenas of 64 MiB, heaps not given back. A third of what is left is kept for that
        // (a 2048² contact solve, estimated at 228 MiB, needs 245–340 MiB of address space).
        left(libc::RLIMIT_AS, used("VmSize:")).map(|b| b / 3 * 2),
        left(libc::RLIMIT_DATA, used("VmData:")),
    ]
    .into_iter()
    .flatten()
    .min()
}

/// What the memory limits of the control groups listed in `groups` (the text of
/// /proc/self/cgroup), mounted at `root`, leave [bytes]: for the group and each group above it
/// (the limits nest), its limit less the memory it holds that cannot be reclaimed (anonymous
/// memory; the page cache gives way), the smallest; `None` when no limit is set or readable.
/// cgroup v2 (`memory.max`) and v1 (`memory/memory.limit_in_bytes`). Inside a container the
/// mount shows the container's own group at its root: a path missing below it falls back to it.
fn cgroup_left(root: &Path, groups: &str) -> Option<u64> {
    let v2 = groups.lines().find_map(|l| l.strip_prefix("0::"));
    let v1 = || {
        groups.lines().find_map(|l| {
            let mut fields = l.splitn(3, ':').skip(1);
            let memory = fields.next()?.split(',').any(|c| c == "memory");
            memory.then(|| fields.next()).flatten()
        })
    };
    let (mount, path, limit_file, anon_key) = match (v2, v1()) {
        (_, Some(path)) => (root.join("memory"), path, "memory.limit_in_bytes", "total_rss"),
        (Some(path), None) => (root.to_path_buf(), path, "memory.max", "anon"),
        (None, None) => return None,
    };
    let group = mount.join(path.trim_start_matches('/'));
    let group = if group.is_dir() { group } else { mount.clone() };
    let read = |dir: &Path, file: &str| std::fs::read_to_string(dir.join(file)).ok();
    group
        .ancestors()
        .take_while(|dir| dir.starts_with(&mount))
        .filter_map(|dir| {
            // "max" (v2) or a huge number (v1's unlimited, rounded to a page) is no limit.
            let limit = read(dir, limit_file)?.trim().parse::<u64>().ok().filter(|&l| l < 1 << 62)?;
            let stat = read(dir, "memory.stat").unwrap_or_default();
            let held = stat
                .lines()
                .find_map(|l| l.strip_prefix(anon_key)?.strip_prefix(' ')?.trim().parse::<u64>().ok())
                .unwrap_or(0);
            Some(limit.saturating_sub(held))
        })
        .min()
}

/// What [`check_memory`] says of an estimate over what is available.
const MORE_THAN_AVAILABLE: &str = "of memory, more than the";

/// What [`reserve`] says of an allocation that failed.
const OUT_OF_MEMORY: &str = "out of memory:";

/// Whether `what`, estimated to need `bytes` of memory, fits in [`available_memory`]; the
/// reason, naming the estimate, when it does not.
pub fn check_memory(bytes: u64, what: &str) -> std::result::Result<(), String> {
    match available_memory() {
        Some(free) if bytes > free => Err(format!(
            "{what} needs about {} {MORE_THAN_AVAILABLE} {} available (free memory, or the limit of ulimit -v)",
            gib(bytes),
            gib(free)
        )),
        _ => Ok(()),
    }
}

/// Whether `message`, an error's line, is a refusal of [`check_memory`] or [`reserve`]: memory
/// that is not there, not a bad input (Python raises `MemoryError` for it).
pub fn is_out_of_memory(message: &str) -> bool {
    message.contains(MORE_THAN_AVAILABLE) || message.contains(OUT_OF_MEMORY)
}

/// The memory `bytes_per_point` × nx × ny \[bytes], saturating.
pub fn grid_memory(nx: usize, ny: usize, bytes_per_point: u64) -> u64 {
    (nx as u64).saturating_mul(ny as u64).saturating_mul(bytes_per_point)
}

/// `n` zeros, or the reason when the memory for them cannot be had (`what` names them).
pub fn zeroed(n: usize, what: &str) -> std::result::Result<Vec<f64>, String> {
    let mut v = Vec::new();
    reserve(&mut v, n, what)?;
    v.resize(n, 0.0);
    Ok(v)
}

/// The items of `items` (decoded values, as many as their bytes allow) in a vector reserved
/// fallibly, or the reason when the memory cannot be had (`what` names them).
pub fn collected<T>(items: impl ExactSizeIterator<Item = T>, what: &str) -> std::result::Result<Vec<T>, String> {
    let mut v = Vec::new();
    reserve(&mut v, items.len(), what)?;
    v.extend(items);
    Ok(v)
}

/// Room for `n` more items in `v`, or the reason when the memory cannot be had (`what` names
/// them): a failed allocation is an error, not an abort.
pub fn reserve<T>(v: &mut Vec<T>, n: usize, what: &str) -> std::result::Result<(), String> {
    v.try_reserve_exact(n).map_err(|_| {
        let bytes = (n as u64).saturating_mul(std::mem::size_of::<T>() as u64);
        format!("{OUT_OF_MEMORY} {} for {what} could not be allocated", gib(bytes))
    })
}

/// `bytes` in GiB, or MiB below one GiB.
pub(crate) fn gib(bytes: u64) -> String {
    match bytes as f64 / (1u64 << 30) as f64 {
        g if g >= 1.0 => format!("{g:.1} GiB"),
        g => format!("{:.0} MiB", (g * 1024.0).ceil()),
    }
}

/// The file at `path`, opened for reading if it is a regular file. It is opened without
/// blocking (a pipe with no writer would block an ordinary open), then checked.
fn open_regular(path: &Path) -> Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| Error::io(path, e))?;
    let kind = file.metadata().map_err(|e| Error::io(path, e))?.file_type();
    if !kind.is_file() {
        let what = if kind.is_dir() { "a directory" } else { "not a regular file (a device, pipe or socket)" };
        return Err(Error::file(path, format!("{what}: asperity reads its inputs from regular files only")));
    }
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A container's or batch job's memory limit counts: the tightest of the group and those
    /// above it, less what they hold that cannot be reclaimed; no limit, no answer.
    #[test]
    fn control_group_limits_count() {
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        let write = |dir: &Path, limit: &str, stat: &str| {
            std::fs::create_dir_all(dir).unwrap();
            std::fs::write(dir.join("memory.max"), limit).unwrap();
            std::fs::write(dir.join("memory.stat"), stat).unwrap();
        };
        write(r, "max\n", "anon 5\n");
        write(&r.join("slurm/job7"), "4096\n", "anon_thp 9\nanon 1000\nfile 50000\n");
        assert_eq!(cgroup_left(r, "0::/slurm/job7\n"), Some(3096));
        write(&r.join("slurm"), "2048\n", "anon 1500\n");
        assert_eq!(cgroup_left(r, "0::/slurm/job7\n"), Some(548));
        assert_eq!(cgroup_left(r, "0::/\n"), None);
        // v1, in a container whose own group is the mount's root; the host's path is not there.
        let m = r.join("memory");
        std::fs::create_dir_all(&m).unwrap();
        std::fs::write(m.join("memory.limit_in_bytes"), "10000\n").unwrap();
        std::fs::write(m.join("memory.stat"), "rss 1\ntotal_rss 2500\n").unwrap();
        assert_eq!(cgroup_left(r, "4:memory:/process_api/abc\n0::/\n"), Some(7500));
        std::fs::write(m.join("memory.limit_in_bytes"), "9223372036854771712\n").unwrap();
        assert_eq!(cgroup_left(r, "4:cpu,memory:/x\n"), None);
    }

    #[test]
    fn grids_are_checked_against_the_limit() {
        let l = Limits::default();
        assert!(l.check_grid(16384, 16384).is_ok());
        let e = l.check_grid(20000, 20000).unwrap_err();
        assert!(e.contains("20000 × 20000") && e.contains("400000000 points") && e.contains("--max-points"), "{e}");
        assert!(l.check_grid(usize::MAX, 3).unwrap_err().contains("more points than can be counted"));
        assert!(Limits::new(100, "--max-points").unwrap().check_grid(11, 10).is_err());
        assert!(Limits::new(3, "--max-points").is_err());
    }

    #[test]
    fn memory_is_estimated_against_what_is_available() {
        let free = available_memory().expect("Linux states its available memory");
        assert!(free > 1 << 20, "{free}");
        assert!(check_memory(1 << 20, "a small map").is_ok());
        let e = check_memory(u64::MAX, "a 1 × 1 grid").unwrap_err();
        assert!(e.starts_with("a 1 × 1 grid needs about 17179869184.0 GiB of memory, more than the "), "{e}");
        assert_eq!(grid_memory(8192, 8192, CONTACT_BYTES_PER_POINT), 3_825_205_248);
        assert_eq!(grid_memory(usize::MAX, 3, 8), u64::MAX);
        assert_eq!((gib(3 << 29), gib(5 << 20)), ("1.5 GiB".to_string(), "5 MiB".to_string()));
        assert_eq!(zeroed(3, "x").unwrap(), vec![0.0; 3]);
        let e = zeroed(usize::MAX / 8, "the heights").unwrap_err();
        assert!(e.starts_with("out of memory: ") && e.ends_with(" GiB for the heights could not be allocated"), "{e}");
        assert!(is_out_of_memory(&e) && is_out_of_memory(&check_memory(u64::MAX, "a grid").unwrap_err()));
        assert!(!is_out_of_memory("--load: must be positive and finite, got -1 N"));
    }

    #[test]
    fn threads_are_bounded() {
        use std::ffi::OsStr;
        assert_eq!(threads_asked(None, 8), Ok(8));
        assert_eq!(threads_asked(Some(OsStr::new("0")), 8), Ok(8));
        assert_eq!(threads_asked(Some(OsStr::new(" 3 ")), 8), Ok(3));
        assert_eq!(threads_asked(Some(OsStr::new("512")), 8), Ok(512));
        let e = threads_asked(Some(OsStr::new("513")), 8).unwrap_err();
        assert!(e.starts_with("513 threads is more than the 512 asperity runs on 8 available cores"), "{e}");
        assert!(threads_asked(Some(OsStr::new("4097")), 1000).unwrap_err().contains("the 4096 asperity runs"));
        assert!(threads_asked(Some(OsStr::new("-1")), 8).unwrap_err().contains("'-1' is not a number of threads"));
    }

    #[test]
    fn only_regular_files_are_read() {
        let l = Limits::default();
        let dir = tempfile::tempdir().unwrap();
        let e = l.read_file(dir.path()).unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
        let e = l.read_file(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.starts_with("/dev/zero: not a regular file"), "{e}");
        let fifo = dir.path().join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert!(l.read_file(&fifo).unwrap_err().to_string().contains("not a regular file"));
        let small = Limits::new(4, "--max-points").unwrap();
        let big = dir.path().join("big");
        std::fs::write(&big, vec![b' '; (small.max_file_bytes() + 1) as usize]).unwrap();
        assert!(small.read_file(&big).unwrap_err().to_string().contains("raise it with --max-points"));
        std::fs::write(&big, b"12").unwrap();
        assert_eq!(small.read_text(&big).unwrap(), "12");
    }
}
