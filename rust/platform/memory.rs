//! Memory that a computation needs, requested so that a shortage is an error, not an abort.
//!
//! Rust aborts the process when an allocation fails, and faer allocates its temporaries
//! infallibly. So the memory a computation will need is requested once before it starts
//! ([`reserve`]): a request that the system refuses (an address-space limit, a size beyond the
//! machine) becomes [`Error::OutOfMemory`], and a granted one is released at once and is there
//! when the computation asks for it piece by piece. Buffers whose size the caller chooses are
//! made with [`try_vec`].
//!
//! # faer's matrix-product workspace
//!
//! faer's matrix-product kernel for x86-64 (the `private-gemm-x86` crate) packs its operands
//! into a buffer that each thread allocates on its first product above faer's small-product
//! threshold (16^3 multiply-adds): twice the last-level cache, as the operating system reports
//! it, whatever the size of the product. That is 4 to 64 MiB on desktop processors, but 520 MiB
//! on a virtual machine that reports a server's 260 MiB L3; the pages are reserved, not touched,
//! so they cost address space, not memory. [`ensure_product_workspace`] reserves that much
//! before the first product of each computing thread and then makes the kernel allocate its
//! buffer, so that a thread that cannot have it fails with [`Error::OutOfMemory`] before the
//! computation starts.

use super::threads;
use crate::error::Error;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use std::cell::Cell;
use std::sync::atomic::Ordering;
use std::sync::{Mutex, OnceLock};

/// Requests `bytes` of memory and releases them at once; `Err(Error::OutOfMemory)` if the system
/// refuses.
pub fn reserve(bytes: usize) -> Result<(), Error> {
    let mut block: Vec<u8> = Vec::new();
    block
        .try_reserve_exact(bytes)
        .map_err(|_| Error::OutOfMemory { bytes })?;
    // The block escapes, so the optimiser cannot remove the request as unused.
    std::hint::black_box(block.as_ptr());
    Ok(())
}

/// A vector of `len` copies of `value`, or `Err(Error::OutOfMemory)`.
pub fn try_vec<T: Clone>(len: usize, value: T) -> Result<Vec<T>, Error> {
    let bytes = len.saturating_mul(std::mem::size_of::<T>());
    let mut out = Vec::new();
    out.try_reserve_exact(len)
        .map_err(|_| Error::OutOfMemory { bytes })?;
    out.resize(len, value);
    Ok(out)
}

/// The size of the largest data or unified cache the operating system reports, in bytes
/// (Linux: sysfs; elsewhere, or if unreadable, a generous 64 MiB).
fn last_level_cache_bytes() -> usize {
    const FALLBACK: usize = 64 << 20;
    #[cfg(target_os = "linux")]
    {
        let largest = std::fs::read_dir("/sys/devices/system/cpu")
            .into_iter()
            .flatten()
            .flatten()
            .filter(|cpu| cpu.file_name().to_string_lossy().starts_with("cpu"))
            .flat_map(|cpu| {
                std::fs::read_dir(cpu.path().join("cache"))
                    .into_iter()
                    .flatten()
            })
            .flatten()
            .filter_map(|index| std::fs::read_to_string(index.path().join("size")).ok())
            .filter_map(|size| parse_cache_size(size.trim()))
            .max();
        largest.unwrap_or(FALLBACK)
    }
    #[cfg(not(target_os = "linux"))]
    {
        FALLBACK
    }
}

/// "32K", "4096K", "260M" or a plain number of bytes, as sysfs writes cache sizes.
fn parse_cache_size(text: &str) -> Option<usize> {
    let (digits, unit) = match text.as_bytes().last()? {
        b'K' => (&text[..text.len() - 1], 1 << 10),
        b'M' => (&text[..text.len() - 1], 1 << 20),
        b'G' => (&text[..text.len() - 1], 1 << 30),
        _ => (text, 1),
    };
    digits.parse::<usize>().ok()?.checked_mul(unit)
}

/// The bytes to reserve for the product kernel's buffer: twice its cache estimate (at least
/// 2 MiB, as the kernel assumes), plus a margin for what the system and the allocators map
/// between the reservation and the buffer (a new thread's malloc arena, say).
pub fn product_workspace_bytes() -> usize {
    static BYTES: OnceLock<usize> = OnceLock::new();
    *BYTES.get_or_init(|| {
        let cache = last_level_cache_bytes().max(2 << 20);
        cache
            .saturating_mul(2)
            .saturating_add(PRODUCT_WORKSPACE_MARGIN)
    })
}

/// See [`product_workspace_bytes`].
const PRODUCT_WORKSPACE_MARGIN: usize = 16 << 20;

/// Matrices of at most this order multiply through faer's small-product kernel (16^3
/// multiply-adds at most), which needs no workspace.
pub const SMALL_PRODUCT_MAX_ORDER: usize = 16;

thread_local! {
    static PRODUCT_WORKSPACE_READY: Cell<bool> = const { Cell::new(false) };
}

/// Held while a thread reserves the workspace and has the kernel allocate it, so that two
/// threads do not both count on the same free address space.
static PRODUCT_WORKSPACE_LOCK: Mutex<()> = Mutex::new(());

/// Whether this thread holds faer's product workspace.
pub fn has_product_workspace() -> bool {
    PRODUCT_WORKSPACE_READY.get()
}

/// Makes sure this thread holds faer's product workspace (see the module documentation), or
/// returns `Err(Error::OutOfMemory)` if it cannot be had. Costs a thread-local load once done.
pub fn ensure_product_workspace() -> Result<(), Error> {
    if PRODUCT_WORKSPACE_READY.get() {
        return Ok(());
    }
    // A product just above faer's small-product threshold, whose operands are made first: the
    // kernel allocates its buffer right after the reservation, while the address space is known
    // to be there.
    const ORDER: usize = 17;
    let a = Mat::<f64>::zeros(ORDER, ORDER);
    let mut c = Mat::<f64>::zeros(ORDER, ORDER);
    let _lock = PRODUCT_WORKSPACE_LOCK
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    reserve(product_workspace_bytes())?;
    matmul(
        c.as_mut(),
        Accum::Replace,
        a.as_ref(),
        a.as_ref(),
        1.0,
        Par::Seq,
    );
    PRODUCT_WORKSPACE_READY.set(true);
    Ok(())
}

/// [`ensure_product_workspace`] on every thread of the pool parallel work runs on
/// ([`threads`]), for a computation whose faer kernels may run in parallel. Call it from
/// outside the pool. Once done, a pool's flag stays true for its life.
pub fn ensure_pool_product_workspace() -> Result<(), Error> {
    let chosen = threads::chosen();
    let flag = chosen
        .as_ref()
        .map_or(&threads::GLOBAL_PRODUCT_WORKSPACE, |pool| {
            &pool.product_workspace
        });
    if flag.load(Ordering::Acquire) {
        return Ok(());
    }
    let outcomes = match &chosen {
        Some(pool) => pool.threads.broadcast(|_| ensure_product_workspace()),
        None => rayon::broadcast(|_| ensure_product_workspace()),
    };
    outcomes.into_iter().collect::<Result<Vec<()>, Error>>()?;
    flag.store(true, Ordering::Release);
    Ok(())
}

/// Whether faer's kernels may run in parallel on the pool: only once every thread of the pool
/// holds its product workspace ([`ensure_pool_product_workspace`]); otherwise they run on the
/// computing thread alone.
pub fn parallel_products_allowed() -> bool {
    threads::chosen().map_or_else(
        || threads::GLOBAL_PRODUCT_WORKSPACE.load(Ordering::Acquire),
        |pool| pool.product_workspace.load(Ordering::Acquire),
    )
}
