//! The Python bindings (cargo feature `python`): the only PyO3 code in the crate.
//!
//! One file per module of the Python package, each converting its arguments, running the core
//! and making its results through the three shared pieces:
//!
//! * [`conversion`]: every argument becomes an owned copy in C order, whatever its layout,
//!   before anything is computed; every result is a new C-ordered array, checked for overflow.
//! * [`compute`]: the computation runs with the GIL held, released, or released and
//!   interruptible by Ctrl-C, by its cost, after the memory it needs has been requested.
//! * [`errors`]: each core error maps to one exception class of `aerocontrol.exceptions`
//!   (MemoryError and KeyboardInterrupt for a refused allocation and an interruption).

mod batch;
mod compute;
mod controllability;
mod conversion;
mod errors;
mod flight;
mod frequency;
mod linalg;
mod loops;
mod modal;
mod placement;
mod responses;
mod riccati;
mod statespace;
mod transfer;

use pyo3::prelude::*;

/// The native core of aerocontrol; use the `aerocontrol` package, not this module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Every kernel whose size warrants threads gets its Par explicitly; faer's convenience
    // methods (small QR, LU and SVD in the placement code) follow the global setting, whose
    // default, rayon, costs more in dispatch than a 4 x 4 factorisation takes.
    faer::set_global_parallelism(faer::Par::Seq);
    errors::load(m.py())?;
    m.add_function(wrap_pyfunction!(errors::exception_classes, m)?)?;
    linalg::register(m)?;
    statespace::register(m)?;
    responses::register(m)?;
    frequency::register(m)?;
    loops::register(m)?;
    transfer::register(m)?;
    modal::register(m)?;
    controllability::register(m)?;
    placement::register(m)?;
    riccati::register(m)?;
    batch::register(m)?;
    flight::register(m)?;
    compute::register(m)?;
    m.add(
        "EXACT_NORM_MAX_ORDER",
        crate::linalg::expm::EXACT_NORM_MAX_ORDER,
    )?;
    m.add("SMALL_MAX_ORDER", crate::linalg::expm::SMALL_MAX_ORDER)?;
    m.add(
        "RESCALE_EXPONENT",
        crate::control::margins::RESCALE_EXPONENT,
    )?;
    m.add("FMA_KERNELS", crate::platform::dispatch::fma_available())?;
    m.add(
        "ILL_CONDITIONED_CONTROLLABILITY",
        crate::control::placement::ILL_CONDITIONED_CONTROLLABILITY,
    )?;
    m.add(
        "POLE_ERROR_WARNING",
        crate::control::placement::POLE_ERROR_WARNING,
    )?;
    m.add(
        "PRODUCT_WORKSPACE_BYTES",
        crate::platform::memory::product_workspace_bytes(),
    )?;
    Ok(())
}
