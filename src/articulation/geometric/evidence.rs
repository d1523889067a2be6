//! How strongly a part's points prefer one motion hypothesis over another: a paired z test over
//! the points' residuals (and over their colour differences), and the level past which it
//! decides.

use super::registration::PointFit;

/// The evidence ([`evidence`]) past which one hypothesis counts as decisively better than
/// another. A single comparison is decisive at the z whose Gaussian log Bayes factor, z² / 2,
/// is ln 100 (the top of Jeffreys' scale): 3.03, a one-sided chance of 0.12 % that noise alone
/// shows it. A part's motion is compared with up to five hypotheses (the other type, not
/// moving, three other optima), so that chance is split five ways (Bonferroni): z 3.49.
pub const DECISIVE: f64 = 3.490_951_347_110_105;

/// The evidence that the motion fitted as `a` explains a part's two clouds better than `b`
/// does (positive: `a` fits better), as a paired z statistic over the points (Vuong's test for
/// non-nested models, Econometrica 1989): per point the difference of its two squared
/// residuals, each capped at the better fit's outlier bound (a point neither explains, a
/// surface seen in one state only, counts alike under both), and the mean difference over its
/// standard error. A ratio of summed residuals grows with the number of points whether or not
/// the difference is systematic; this measures the difference against its own scatter. Both
/// directions match the same surfaces, so half the points count as independent. A model with
/// more free parameters pays Schwarz's (BIC) ½ ln n per parameter, as in Vuong's corrected
/// statistic: a hinge turned half a turn about a flat part's normal fits a slide of it as
/// well, and must not win on the noise its two extra parameters absorb.
pub fn evidence(a: &PointFit, b: &PointFit) -> f64 {
    let cap = a.cap.min(b.cap);
    let pairs = || a.squared.iter().zip(&b.squared);
    let n = 0.5 * a.squared.len().min(b.squared.len()) as f64;
    // The residual variance of the better-fitting model, for the Gaussian log-likelihood.
    let variance = pairs().map(|(x, y)| x.min(*y).min(cap)).sum::<f64>() / (2.0 * n).max(1.0);
    let extra = a.dims as f64 - b.dims as f64;
    // Per point: a Gaussian log-likelihood difference of d / (2 s²) nats; the penalty of
    // extra · ½ ln n nats over the n points, spread over them.
    let penalty = 2.0 * variance * extra * 0.5 * n.max(1.0).ln() / n.max(1.0);
    paired_z(pairs().map(|(x, y)| y.min(cap) - x.min(cap) - penalty))
}

/// The evidence, as in [`evidence`], that the colours agree better under `a` than under `b`.
pub fn color_evidence(a: &PointFit, b: &PointFit) -> f64 {
    paired_z(a.colors.iter().zip(&b.colors).map(|(x, y)| y - x))
}

/// The mean of paired differences `d` over its standard error, half the pairs counted as
/// independent (see [`evidence`]).
fn paired_z(d: impl Iterator<Item = f64>) -> f64 {
    let d: Vec<f64> = d.collect();
    let n = d.len() as f64;
    if n < 2.0 {
        return 0.0;
    }
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let error = (var / (0.5 * n)).sqrt();
    if error > 0.0 {
        mean / error
    } else if mean == 0.0 {
        0.0
    } else {
        // Exactly the same difference at every point: no scatter to doubt it by.
        mean.signum() * f64::INFINITY
    }
}
