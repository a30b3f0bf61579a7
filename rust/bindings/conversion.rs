//! The one path by which arguments enter the core and results leave it.
//!
//! # Arguments
//!
//! Every array argument becomes a [`Real`] (or, for requested poles, a [`Complex`]): an owned
//! copy of its values in C order. A float64 ndarray is read directly, through its shape and byte
//! strides, whatever its layout (C or Fortran order, transposed and sliced views, negative,
//! zero and odd strides, misaligned data); anything else (lists, other dtypes, non-native byte
//! order, objects with `__array__`) is first converted by `aerocontrol._validation.real_array`,
//! which names the argument in its errors. So every layout gives bitwise the result of its
//! C-ordered copy, and the core never reads memory that Python code could change or free while
//! it works: a binding converts all its arguments (which may run the caller's Python code)
//! before it computes, and computes on its own copies, with the GIL released when the work is
//! long ([`crate::bindings::compute`]).
//!
//! # Results
//!
//! Results are new C-ordered numpy arrays, made through [`Outputs`], which notes every
//! non-finite value of a result that should be finite and issues one `NumericalOverflowWarning`
//! naming the results that overflowed.

use super::errors::{Class, to_py_err, warn};
use crate::control::batch::MatrixStack;
use crate::error::Error;
use faer::{Mat, MatMut, MatRef, c64};
use numpy::PyUntypedArrayMethods;
use numpy::npyffi::{PY_ARRAY_API, npy_intp};
use numpy::{Element, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray};
use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

/// `aerocontrol._validation.real_array`.
static REAL_ARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
/// `aerocontrol.placement._poles`.
static POLES: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

pub(crate) fn python_function<'py>(
    py: Python<'py>,
    cell: &'static PyOnceLock<Py<PyAny>>,
    module: &str,
    name: &str,
) -> PyResult<&'py Bound<'py, PyAny>> {
    Ok(cell
        .get_or_try_init(py, || {
            PyModule::import(py, module)?
                .getattr(name)
                .map(Bound::unbind)
        })?
        .bind(py))
}

/// The number of entries of an array of this shape, or MemoryError if it cannot be addressed.
pub fn entries(shape: &[usize]) -> PyResult<usize> {
    shape
        .iter()
        .try_fold(1usize, |total, &d| total.checked_mul(d))
        .filter(|&total| total <= isize::MAX as usize / std::mem::size_of::<c64>())
        .ok_or_else(|| {
            PyMemoryError::new_err(format!(
                "an array of shape {shape:?} is too large to allocate"
            ))
        })
}

/// The values of an ndarray of element type `T`, copied in C order, whatever its strides and
/// alignment.
pub fn copy_values<T: Element + Copy>(
    py: Python<'_>,
    array: &Bound<'_, PyArrayDyn<T>>,
) -> PyResult<Vec<T>> {
    let shape = array.shape();
    let count = entries(shape)?;
    let mut values = Vec::new();
    values.try_reserve_exact(count).map_err(|_| {
        to_py_err(
            py,
            Error::OutOfMemory {
                bytes: count.saturating_mul(std::mem::size_of::<T>()),
            },
        )
    })?;
    if count == 0 {
        return Ok(values);
    }
    let base = array.data().cast::<u8>().cast_const();
    let aligned = (base as usize).is_multiple_of(std::mem::align_of::<T>());
    if array.is_c_contiguous() && aligned {
        // SAFETY: a C-contiguous, aligned array holds `count` values of T from `base`, and the
        // GIL is held, so no Python code changes them meanwhile.
        values.extend_from_slice(unsafe { std::slice::from_raw_parts(base.cast::<T>(), count) });
        return Ok(values);
    }
    // Any other layout: row by row along the last axis, by byte offsets and unaligned loads
    // (numpy allows strides that are not multiples of the item size, and misaligned data).
    let strides = array.strides();
    let (inner_len, inner_stride) = match shape.len() {
        0 => (1, 0),
        d => (shape[d - 1], strides[d - 1]),
    };
    let outer_shape = &shape[..shape.len().saturating_sub(1)];
    let mut index = vec![0usize; outer_shape.len()];
    for _ in 0..count / inner_len {
        let row: isize = index
            .iter()
            .zip(strides)
            .map(|(&i, &s)| i as isize * s)
            .sum();
        for j in 0..inner_len {
            let offset = row + j as isize * inner_stride;
            // SAFETY: the index stays within the shape, so the offset addresses one of the
            // array's own elements; the load is unaligned-safe; the GIL is held.
            values.push(unsafe { base.wrapping_offset(offset).cast::<T>().read_unaligned() });
        }
        for axis in (0..outer_shape.len()).rev() {
            index[axis] += 1;
            if index[axis] < outer_shape[axis] {
                break;
            }
            index[axis] = 0;
        }
    }
    Ok(values)
}

/// A real array argument: its name, shape and values in C order.
#[derive(Debug)]
pub struct Real {
    name: &'static str,
    shape: Vec<usize>,
    values: Vec<f64>,
}

impl Real {
    /// Converts the argument `name` (see the module documentation).
    pub fn convert(py: Python<'_>, value: &Bound<'_, PyAny>, name: &'static str) -> PyResult<Self> {
        let converted;
        let array = match value.cast::<PyArrayDyn<f64>>() {
            Ok(array) => array,
            Err(_) => {
                converted =
                    python_function(py, &REAL_ARRAY, "aerocontrol._validation", "real_array")?
                        .call1((value, name))?
                        .cast_into::<PyArrayDyn<f64>>()?;
                &converted
            }
        };
        Ok(Self {
            name,
            shape: array.shape().to_vec(),
            values: copy_values(py, array)?,
        })
    }

    /// Converts an optional argument.
    pub fn convert_optional(
        py: Python<'_>,
        value: Option<&Bound<'_, PyAny>>,
        name: &'static str,
    ) -> PyResult<Option<Self>> {
        value.map(|v| Self::convert(py, v, name)).transpose()
    }

    pub fn name(&self) -> &'static str {
        self.name
    }

    pub fn shape(&self) -> &[usize] {
        &self.shape
    }

    /// All values, in C order.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    fn wrong_dimensions(&self, expected: &'static str) -> Error {
        Error::WrongDimensions {
            arg: self.name,
            expected,
            shape: self.shape.clone(),
        }
    }

    /// The argument as a matrix; an error unless it is 2-D.
    pub fn matrix(&self) -> Result<MatRef<'_, f64>, Error> {
        match self.shape[..] {
            [rows, cols] => Ok(MatRef::from_row_major_slice(&self.values, rows, cols)),
            _ => Err(self.wrong_dimensions("a 2-D matrix")),
        }
    }

    /// A weight of a Riccati equation as a matrix, shaped as `numpy.atleast_2d` shapes it
    /// (python-control accepts R = 1): a scalar as 1 x 1, a 1-D array of length k as 1 x k.
    pub fn weight(&self) -> Result<MatRef<'_, f64>, Error> {
        match self.shape[..] {
            [] => Ok(MatRef::from_row_major_slice(&self.values, 1, 1)),
            [cols] => Ok(MatRef::from_row_major_slice(&self.values, 1, cols)),
            [rows, cols] => Ok(MatRef::from_row_major_slice(&self.values, rows, cols)),
            _ => Err(self.wrong_dimensions("a 2-D matrix or a scalar")),
        }
    }

    /// The argument as the input matrix of a single-input function: a 1-D b as the n x 1
    /// column, a 2-D one as it is.
    pub fn input_column(&self) -> Result<MatRef<'_, f64>, Error> {
        match self.shape[..] {
            [len] => Ok(MatRef::from_column_major_slice(&self.values, len, 1)),
            _ => self.matrix(),
        }
    }

    /// The argument as a vector; an error (`expected` describes it) unless it is 1-D.
    pub fn vector(&self, expected: &'static str) -> Result<&[f64], Error> {
        match self.shape[..] {
            [_] => Ok(&self.values),
            _ => Err(self.wrong_dimensions(expected)),
        }
    }

    /// The argument as a stack of matrices; an error unless it is 3-D.
    pub fn stack(&self) -> Result<MatrixStack<'_>, Error> {
        match self.shape[..] {
            [count, rows, cols] => MatrixStack::new(&self.values, count, rows, cols),
            _ => Err(self.wrong_dimensions("a 3-D stack of matrices")),
        }
    }
}

/// A complex array argument (requested poles): its shape and values in C order.
#[derive(Debug)]
pub struct Complex {
    pub shape: Vec<usize>,
    pub values: Vec<c64>,
}

impl Complex {
    /// Converts requested poles: a complex128 array is read directly, anything else through
    /// `aerocontrol.placement._poles` (which names `poles` in its errors).
    pub fn poles(py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<Self> {
        let converted;
        let array = match value.cast::<PyArrayDyn<c64>>() {
            Ok(array) => array,
            Err(_) => {
                converted = python_function(py, &POLES, "aerocontrol.placement", "_poles")?
                    .call1((value,))?
                    .cast_into::<PyArrayDyn<c64>>()?;
                &converted
            }
        };
        Ok(Self {
            shape: array.shape().to_vec(),
            values: copy_values(py, array)?,
        })
    }
}

/// A new zero-filled C-ordered array (float64 or complex128), or MemoryError.
pub fn new_array<'py, T: Element>(
    py: Python<'py>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    entries(shape)?;
    let mut dims: Vec<npy_intp> = shape.iter().map(|&d| d as npy_intp).collect();
    let descriptor = T::get_dtype(py).into_dtype_ptr();
    // SAFETY: numpy's PyArray_Zeros with a valid shape and a new reference to the element's
    // descriptor (which it steals); a null result is a raised Python exception.
    let pointer = unsafe {
        PY_ARRAY_API.PyArray_Zeros(py, dims.len() as i32, dims.as_mut_ptr(), descriptor, 0)
    };
    if pointer.is_null() {
        return Err(PyErr::fetch(py));
    }
    // SAFETY: a new, owned ndarray of element type T.
    Ok(unsafe {
        Bound::from_owned_ptr(py, pointer)
            .cast_into_unchecked::<PyUntypedArray>()
            .cast_into_unchecked::<PyArrayDyn<T>>()
    })
}

/// The data of an array created by [`new_array`] and not yet handed to Python.
///
/// # Safety
/// No other reference to the array's data may exist while the slice lives. (The same contract
/// as rust-numpy's `PyArray::as_slice_mut`: the array object is shared, its data is not.)
#[allow(clippy::mut_from_ref)]
pub unsafe fn new_array_data<'a, T: Element>(array: &'a Bound<'_, PyArrayDyn<T>>) -> &'a mut [T] {
    // SAFETY: a new array is C-contiguous and aligned, holding `len` values; exclusive access
    // is the caller's promise.
    unsafe { std::slice::from_raw_parts_mut(array.data(), array.len()) }
}

/// Whether every value is finite.
fn all_finite<T: Copy>(values: &[T], finite: impl Fn(T) -> bool) -> bool {
    values.iter().fold(true, |all, &v| all & finite(v))
}

fn c64_finite(z: c64) -> bool {
    z.re.is_finite() && z.im.is_finite()
}

/// The results of one call, made as numpy arrays, and the names of those that overflowed.
pub struct Outputs<'py> {
    py: Python<'py>,
    overflowed: Vec<&'static str>,
}

impl<'py> Outputs<'py> {
    pub fn new(py: Python<'py>) -> Self {
        Self {
            py,
            overflowed: Vec::new(),
        }
    }

    /// Notes the values of result `name` (filled in place by the core) if any is not finite.
    pub fn check(&mut self, name: &'static str, values: &[f64]) {
        if !all_finite(values, f64::is_finite) {
            self.overflowed.push(name);
        }
    }

    /// Like [`Outputs::check`], for complex values.
    pub fn check_complex(&mut self, name: &'static str, values: &[c64]) {
        if !all_finite(values, c64_finite) {
            self.overflowed.push(name);
        }
    }

    /// A new C-ordered array holding `m`, checked.
    pub fn matrix(
        &mut self,
        name: &'static str,
        m: MatRef<'_, f64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let array = new_array(self.py, &[m.nrows(), m.ncols()])?;
        // SAFETY: the array was just created and is not yet visible to Python.
        let data = unsafe { new_array_data(&array) };
        MatMut::from_row_major_slice_mut(data, m.nrows(), m.ncols()).copy_from(m);
        self.check(name, data);
        Ok(array)
    }

    /// A new C-ordered (k, rows, cols) array holding k matrices of one shape, checked.
    pub fn matrices(
        &mut self,
        name: &'static str,
        matrices: &[Mat<f64>],
        rows: usize,
        cols: usize,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let array = new_array(self.py, &[matrices.len(), rows, cols])?;
        // SAFETY: the array was just created and is not yet visible to Python.
        let data = unsafe { new_array_data(&array) };
        for (index, m) in matrices.iter().enumerate() {
            let chunk = &mut data[index * rows * cols..(index + 1) * rows * cols];
            MatMut::from_row_major_slice_mut(chunk, rows, cols).copy_from(m);
        }
        self.check(name, data);
        Ok(array)
    }

    /// A new array of `shape` holding `values` (C order), checked.
    pub fn real(
        &mut self,
        name: &'static str,
        shape: &[usize],
        values: &[f64],
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        self.check(name, values);
        self.real_as_is(shape, values)
    }

    /// A new array of `shape` holding `values`, which may be infinite or NaN by definition (the
    /// period of a real mode, say): not checked.
    pub fn real_as_is(
        &mut self,
        shape: &[usize],
        values: &[f64],
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let array = new_array(self.py, shape)?;
        // SAFETY: the array was just created and is not yet visible to Python.
        unsafe { new_array_data(&array) }.copy_from_slice(values);
        Ok(array)
    }

    /// A new complex array of `shape` holding `values` (C order), checked.
    pub fn complex(
        &mut self,
        name: &'static str,
        shape: &[usize],
        values: &[c64],
    ) -> PyResult<Bound<'py, PyArrayDyn<c64>>> {
        self.check_complex(name, values);
        let array = new_array(self.py, shape)?;
        // SAFETY: the array was just created and is not yet visible to Python.
        unsafe { new_array_data(&array) }.copy_from_slice(values);
        Ok(array)
    }

    /// A new C-ordered complex array holding `m`, checked.
    pub fn complex_matrix(
        &mut self,
        name: &'static str,
        m: MatRef<'_, c64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<c64>>> {
        let array = new_array::<c64>(self.py, &[m.nrows(), m.ncols()])?;
        // SAFETY: the array was just created and is not yet visible to Python.
        let data = unsafe { new_array_data(&array) };
        MatMut::from_row_major_slice_mut(data, m.nrows(), m.ncols()).copy_from(m);
        self.check_complex(name, data);
        Ok(array)
    }

    /// Issues one `NumericalOverflowWarning` naming the results that overflowed, if any.
    pub fn finish(self) -> PyResult<()> {
        if self.overflowed.is_empty() {
            return Ok(());
        }
        let message = format!(
            "the result overflowed double precision: {} {} infinite or NaN entries",
            self.overflowed.join(", "),
            if self.overflowed.len() == 1 {
                "has"
            } else {
                "have"
            }
        );
        warn(self.py, Class::NumericalOverflowWarning, &message)
    }
}
