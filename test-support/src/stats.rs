//! Pearson's chi-square test with an exact p-value, written independently of
//! the samplers it judges.

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, nine terms; ~1e-15 relative).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + G + 0.5;
    let mut a = C[0];
    for (i, &c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised upper incomplete gamma function `Q(a, x)`.
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let log_prefix = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        // Series for P(a, x).
        let (mut ap, mut term) = (a, 1.0 / a);
        let mut sum = term;
        for _ in 0..100_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * log_prefix.exp()).max(0.0)
    } else {
        // Continued fraction for Q(a, x) (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..100_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (log_prefix.exp() * h).clamp(0.0, 1.0)
    }
}

/// Outcome of a chi-square goodness-of-fit test.
#[derive(Debug, Clone, Copy)]
pub struct ChiSquare {
    /// Pearson's statistic over the merged bins.
    pub statistic: f64,
    /// Degrees of freedom (bins − 1).
    pub dof: usize,
    /// Probability of a statistic at least this large under the hypothesis;
    /// 0 when an outcome of probability zero was observed.
    pub p_value: f64,
}

/// Tests `counts` against the exact `probabilities` (same length).
///
/// Consecutive outcomes are merged into bins of expected count at least
/// `min_expected`, so heavy-tailed distributions with many tiny entries are
/// tested on all of their mass. An observation of an outcome with
/// probability zero fails the test outright.
pub fn chi_square(counts: &[u64], probabilities: &[f64], min_expected: f64) -> ChiSquare {
    assert_eq!(counts.len(), probabilities.len());
    let samples: u64 = counts.iter().sum();
    let n = samples as f64;
    if counts
        .iter()
        .zip(probabilities)
        .any(|(&c, &p)| p == 0.0 && c > 0)
    {
        return ChiSquare {
            statistic: f64::INFINITY,
            dof: 0,
            p_value: 0.0,
        };
    }
    let mut bins: Vec<(f64, f64)> = Vec::new(); // (observed, expected)
    let (mut obs, mut exp) = (0.0, 0.0);
    for (&c, &p) in counts.iter().zip(probabilities) {
        obs += c as f64;
        exp += p * n;
        if exp >= min_expected {
            bins.push((obs, exp));
            (obs, exp) = (0.0, 0.0);
        }
    }
    if exp > 0.0 || obs > 0.0 {
        match bins.last_mut() {
            Some(last) => {
                last.0 += obs;
                last.1 += exp;
            }
            None => bins.push((obs, exp)),
        }
    }
    let statistic: f64 = bins.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum();
    let dof = bins.len().saturating_sub(1);
    let p_value = if dof == 0 {
        1.0
    } else {
        gamma_q(dof as f64 / 2.0, statistic / 2.0)
    };
    ChiSquare {
        statistic,
        dof,
        p_value,
    }
}

/// Neumaier-compensated sum: the reference total the tests compare against.
pub fn exact_sum(values: impl IntoIterator<Item = f64>) -> f64 {
    let (mut sum, mut comp) = (0.0f64, 0.0f64);
    for v in values {
        let t = sum + v;
        if sum.abs() >= v.abs() {
            comp += (sum - t) + v;
        } else {
            comp += (v - t) + sum;
        }
        sum = t;
    }
    sum + comp
}

/// Reference probabilities `w_i / Σw`.
pub fn probabilities(weights: &[f64]) -> Vec<f64> {
    let total = exact_sum(weights.iter().copied());
    weights.iter().map(|&w| w / total).collect()
}

#[cfg(test)]
mod self_check {
    use super::*;

    #[test]
    fn p_values_match_tables() {
        // Critical values of the chi-square distribution at α = 0.001 / 0.05.
        assert!((gamma_q(0.5, 10.828 / 2.0) - 0.001).abs() < 2e-6);
        assert!((gamma_q(5.0, 18.307 / 2.0) - 0.05).abs() < 2e-5);
        assert!((gamma_q(50.0, 124.342 / 2.0) - 0.05).abs() < 2e-4);
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    }
}
