//! 1D and 2D discrete distributions (discrete-sampling): the lookup-table
//! CDF of Šik & Křivánek 2013, Sec. 4, and environment-map directions.

use discrete_sampling::{DiscreteSampler, GuideTable, InvertibleSampler, Sample2D};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use rand::SeedableRng;

use crate::arrays::{self, Int};
use crate::error::{Failure, detached};

/// The generator of the `seed` argument (default 0).
fn rng(seed: Option<&Int>) -> PyResult<rand_pcg::Pcg64Mcg> {
    Ok(rand_pcg::Pcg64Mcg::seed_from_u64(arrays::seed(seed)?))
}

/// `index` (the argument of `pdf` and `invert`) as indices into `len`
/// entries: one out of range (negative, `>= len`) is an error naming the
/// entry and its value, not a probability of 0 or a NaN that a caller
/// would take for an answer.
fn indices(index: &Bound<'_, PyAny>, len: usize) -> PyResult<Vec<usize>> {
    arrays::values_i64(index, "index")?
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            usize::try_from(i).ok().filter(|&i| i < len).ok_or_else(|| {
                Failure::input(format!(
                    "index: entry {k} is {i}, not an index of the {len} entries (0..{})",
                    len.saturating_sub(1)
                ))
                .into()
            })
        })
        .collect()
}

/// Whether `x` is a variate, in `[0, 1)` (NaN is not).
fn is_variate(x: f64) -> bool {
    (0.0..1.0).contains(&x)
}

/// A row of a `(n, 2)` or `(n, 3)` argument as the message prints it.
fn row_text(r: &[f64]) -> String {
    let parts: Vec<String> = r.iter().map(f64::to_string).collect();
    format!("[{}]", parts.join(", "))
}

/// `(n, 2)` points of the unit square `[0, 1)²` (the variates of
/// `sample_u`, the points of `pdf`): a row outside it, or with a NaN, is
/// an error naming `what`, the row and its value.
fn unit_square(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 2]>> {
    let rows = arrays::rows_f64::<2>(obj, what)?;
    if let Some((k, r)) = rows
        .iter()
        .enumerate()
        .find(|(_, r)| !r.iter().all(|&x| is_variate(x)))
    {
        return Err(Failure::input(format!(
            "{what}: row {k} is {}, not in [0, 1)²",
            row_text(r)
        ))
        .into());
    }
    Ok(rows)
}

/// A discrete distribution over `len(weights)` entries, entry `i` with
/// probability `weights[i] / sum(weights)`, sampled by the lookup-table
/// (guide-table) CDF of Šik & Křivánek 2013, Sec. 4: the index bisection
/// would give, for every variate, in one or two loads.
///
/// `weights`: a 1-D array-like of finite non-negative reals, not all zero
/// (else `trilux.InputError` naming the first bad index).
#[pyclass(module = "trilux", frozen)]
pub(crate) struct Distribution1D {
    table: GuideTable,
}

#[pymethods]
impl Distribution1D {
    #[new]
    fn new(weights: &Bound<'_, PyAny>) -> PyResult<Self> {
        let w = arrays::values_f64(weights, "weights")?;
        Ok(Self {
            table: GuideTable::new(&w).map_err(Failure::from)?,
        })
    }

    /// `n` indices drawn with `seed` (default 0), `(n,)` int64.
    #[pyo3(signature = (n, seed = None))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        n: Int,
        seed: Option<Int>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = arrays::count(&n, "n")?;
        let mut rng = rng(seed.as_ref())?;
        let out = detached(py, || {
            let mut out = vec![0usize; n];
            self.table.sample_into(&mut rng, &mut out);
            Ok(out.into_iter().map(|i| i as i64).collect::<Vec<i64>>())
        })?;
        Ok(arrays::vector(py, out))
    }

    /// The indices for your own variates `u` in `[0, 1)` (stratified, QMC),
    /// `(n,)` int64; the order of `u` is kept (inversion of the CDF). A
    /// variate outside `[0, 1)` or NaN raises `trilux.InputError` naming
    /// it.
    fn sample_u<'py>(&self, py: Python<'py>, u: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let u = arrays::values_f64(u, "u")?;
        if let Some((k, x)) = u.iter().enumerate().find(|(_, x)| !is_variate(**x)) {
            return Err(Failure::input(format!("u: entry {k} is {x}, not in [0, 1)")).into());
        }
        let out: Vec<i64> = u.iter().map(|&x| self.table.sample_u(x) as i64).collect();
        Ok(arrays::vector(py, out))
    }

    /// The probability of each index, `(n,)` float64; an index out of
    /// range raises `trilux.InputError` naming it.
    fn pdf<'py>(&self, py: Python<'py>, index: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let index = indices(index, self.table.len())?;
        let out: Vec<f64> = index.iter().map(|&i| self.table.pdf(i)).collect();
        Ok(arrays::vector(py, out))
    }

    /// The smallest variate `u` that `sample_u` maps to each index (the
    /// start of its CDF interval), `(n,)` float64; an index out of range
    /// raises `trilux.InputError` naming it.
    fn invert<'py>(
        &self,
        py: Python<'py>,
        index: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let index = indices(index, self.table.len())?;
        let out: Vec<f64> = index
            .iter()
            .map(|&i| self.table.invert(i).unwrap_or(f64::NAN))
            .collect();
        Ok(arrays::vector(py, out))
    }

    fn __len__(&self) -> usize {
        self.table.len()
    }
}

/// A piecewise-constant density over `[0, 1)²` from an image of weights
/// (marginal over rows + conditional per row, each a guide table):
/// `Distribution2D(image)`, `image` `(H, W)` weights or `(H, W, C)` colour
/// (its Rec. 709 luminance). Points are `[x, y]`, `x` along a row, `y`
/// down the rows (row 0 at `y = 0`), as in the image.
///
/// `Distribution2D.from_equirect(image)` weights row `r` by `sin θ` of
/// its centre, for a latitude–longitude environment map (row 0 the top,
/// `θ = 0`); then `sample_direction` / `pdf_direction` give directions
/// with densities per steradian, in the axes of discrete-sampling's
/// `equirect_direction` (`+y` up: row 0 is `+y`).
#[pyclass(module = "trilux", frozen)]
pub(crate) struct Distribution2D {
    inner: discrete_sampling::Distribution2D,
}

fn weights_2d(image: &Bound<'_, PyAny>) -> PyResult<(Vec<f64>, usize, usize)> {
    let a = arrays::image_array(image, "image")?;
    let w: Vec<f64> = match a.channels {
        1 | 2 => a
            .values
            .chunks_exact(a.channels)
            .map(|p| f64::from(p[0]))
            .collect(),
        _ => a
            .values
            .chunks_exact(a.channels)
            .map(|p| f64::from(discrete_sampling::luminance([p[0], p[1], p[2]])))
            .collect(),
    };
    Ok((w, a.width, a.height))
}

fn samples_out<'py>(py: Python<'py>, s: &[Sample2D]) -> PyResult<Bound<'py, PyTuple>> {
    let points = s.iter().flat_map(|s| s.point).collect();
    let pdf = s.iter().map(|s| s.pdf).collect();
    PyTuple::new(
        py,
        [arrays::matrix(py, points, 2)?, arrays::vector(py, pdf)],
    )
}

#[pymethods]
impl Distribution2D {
    #[new]
    fn new(image: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (w, width, height) = weights_2d(image)?;
        Ok(Self {
            inner: discrete_sampling::Distribution2D::new(&w, width, height)
                .map_err(Failure::from)?,
        })
    }

    /// The distribution of an equirectangular environment map (rows
    /// weighted by `sin θ`).
    #[staticmethod]
    fn from_equirect(image: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (w, width, height) = weights_2d(image)?;
        Ok(Self {
            inner: discrete_sampling::Distribution2D::from_equirect(&w, width, height)
                .map_err(Failure::from)?,
        })
    }

    /// `(width, height)` of the image.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        (self.inner.width(), self.inner.height())
    }

    /// `n` points drawn with `seed`: `(points (n, 2) float64, pdf (n,)
    /// float64)`, the density w.r.t. area in `[0, 1)²`.
    #[pyo3(signature = (n, seed = None))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        n: Int,
        seed: Option<Int>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let n = arrays::count(&n, "n")?;
        let mut rng = rng(seed.as_ref())?;
        let out = detached(py, || {
            let mut out = vec![Sample2D::default(); n];
            self.inner.sample_into(&mut rng, &mut out);
            Ok(out)
        })?;
        samples_out(py, &out)
    }

    /// The points for your own variates `u` `(n, 2)` in `[0, 1)²` (a row
    /// outside it, or with a NaN, raises `trilux.InputError` naming it).
    fn sample_u<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let u = unit_square(u, "u")?;
        let out: Vec<Sample2D> = u.iter().map(|&u| self.inner.sample_u(u)).collect();
        samples_out(py, &out)
    }

    /// The density w.r.t. area at `points` `(n, 2)` in `[0, 1)²`, `(n,)`
    /// float64 (a point outside the square, or with a NaN, raises
    /// `trilux.InputError` naming it).
    fn pdf<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let p = unit_square(points, "points")?;
        Ok(arrays::vector(
            py,
            p.iter().map(|&p| self.inner.pdf(p)).collect(),
        ))
    }

    /// `n` directions drawn with `seed`: `(directions (n, 3) float64 unit
    /// vectors, pdf (n,) float64 per steradian)`, for a path tracer's
    /// light sampling.
    #[pyo3(signature = (n, seed = None))]
    fn sample_direction<'py>(
        &self,
        py: Python<'py>,
        n: Int,
        seed: Option<Int>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        use rand::RngExt;
        let n = arrays::count(&n, "n")?;
        let mut rng = rng(seed.as_ref())?;
        let out = detached(py, || {
            Ok((0..n)
                .map(|_| {
                    let u = [rng.random::<f64>(), rng.random::<f64>()];
                    self.inner.sample_direction(u)
                })
                .collect::<Vec<_>>())
        })?;
        let dirs = out.iter().flat_map(|s| s.direction).collect();
        let pdf = out.iter().map(|s| s.pdf).collect();
        PyTuple::new(py, [arrays::matrix(py, dirs, 3)?, arrays::vector(py, pdf)])
    }

    /// The density per steradian with which `sample_direction` draws each
    /// of `directions` `(n, 3)` (any length; 0 for a zero direction): what
    /// multiple importance sampling needs for a BSDF-sampled direction. A
    /// direction with a NaN or infinite component raises
    /// `trilux.InputError` naming it.
    fn pdf_direction<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let d = arrays::rows_f64::<3>(directions, "directions")?;
        if let Some((k, r)) = d
            .iter()
            .enumerate()
            .find(|(_, r)| !r.iter().all(|x| x.is_finite()))
        {
            return Err(Failure::input(format!(
                "directions: row {k} is {}, not a finite direction",
                row_text(r)
            ))
            .into());
        }
        Ok(arrays::vector(
            py,
            d.iter().map(|&d| self.inner.pdf_direction(d)).collect(),
        ))
    }
}
