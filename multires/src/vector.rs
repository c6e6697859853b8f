//! Parallel vector operations whose results do not depend on the number
//! of threads: work is split into fixed-size chunks and partial sums are
//! added in chunk order.

use rayon::prelude::*;

/// Elements per parallel task: large enough to amortise scheduling, small
/// enough to balance two to 64 threads on 10⁵–10⁷ unknowns.
pub(crate) const CHUNK: usize = 1 << 13;

/// `Σ f(chunk of a, chunk of b)` with the partial sums added in order.
#[inline]
fn reduce2(a: &[f64], b: &[f64], f: impl Fn(&[f64], &[f64]) -> f64 + Sync) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    if a.len() <= CHUNK {
        return f(a, b);
    }
    let partial: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(a, b)| f(a, b))
        .collect();
    partial.iter().sum()
}

/// `a · b`.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    reduce2(a, b, |a, b| a.iter().zip(b).map(|(x, y)| x * y).sum())
}

/// `‖a‖₂`.
pub(crate) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// `y ← y + α x`.
pub(crate) fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    y.par_chunks_mut(CHUNK)
        .zip(x.par_chunks(CHUNK))
        .for_each(|(y, x)| {
            for (y, x) in y.iter_mut().zip(x) {
                *y += alpha * x;
            }
        });
}

/// `y ← x + β y`.
pub(crate) fn xpby(x: &[f64], beta: f64, y: &mut [f64]) {
    y.par_chunks_mut(CHUNK)
        .zip(x.par_chunks(CHUNK))
        .for_each(|(y, x)| {
            for (y, x) in y.iter_mut().zip(x) {
                *y = x + beta * *y;
            }
        });
}

/// `out ← a ⊙ b` (element-wise): a diagonal preconditioner applied.
pub(crate) fn scale(a: &[f64], b: &[f64], out: &mut [f64]) {
    out.par_chunks_mut(CHUNK)
        .zip(a.par_chunks(CHUNK).zip(b.par_chunks(CHUNK)))
        .for_each(|(out, (a, b))| {
            for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
                *o = a * b;
            }
        });
}

/// `x ← x + α p`, `r ← r − α q`, returning `‖r‖²`: CG's update in one pass.
pub(crate) fn cg_update(alpha: f64, p: &[f64], q: &[f64], x: &mut [f64], r: &mut [f64]) -> f64 {
    let partial: Vec<f64> = x
        .par_chunks_mut(CHUNK)
        .zip(r.par_chunks_mut(CHUNK))
        .zip(p.par_chunks(CHUNK).zip(q.par_chunks(CHUNK)))
        .map(|((x, r), (p, q))| {
            let mut s = 0.0;
            for i in 0..x.len() {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
                s += r[i] * r[i];
            }
            s
        })
        .collect();
    partial.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reductions_match_a_serial_sum_closely() {
        let a: Vec<f64> = (0..100_003)
            .map(|i| ((i * 37) % 101) as f64 - 50.0)
            .collect();
        let b: Vec<f64> = (0..100_003)
            .map(|i| ((i * 11) % 17) as f64 * 0.25)
            .collect();
        let serial: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        assert!((dot(&a, &b) - serial).abs() <= 1e-9 * serial.abs().max(1.0));
        let mut y = b.clone();
        axpy(2.0, &a, &mut y);
        assert_eq!(y[5], b[5] + 2.0 * a[5]);
        let mut z = b.clone();
        xpby(&a, 0.5, &mut z);
        assert_eq!(z[99_999], a[99_999] + 0.5 * b[99_999]);
    }
}
