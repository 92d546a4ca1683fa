//! Per flute count: representative values of H_k (docs/spec/engagement.md §5.7), machining time (§5.8),
//! multi-tooth intervals, and the recommendation under the two limits (§5.9) and the machine's:
//! a flute count whose spindle torque or power (the phase-mean values the torque chart draws),
//! spindle speed or feed exceeds the machine's is never recommended.

use super::answer::{EngagementSample, FluteLimit, FluteResult, OverLimit};
use super::force::{ForceModel, power_kw};
use super::job::{FeedMode, Job};
use super::limits::{RESONANCE_BAND, resonance, tooth_passing_hz};
use super::request::Representative;
use super::series::Series;
use crate::capability::Control;
use crate::error::{SolverError, Warning};

/// Relative slack of the limit comparisons, so a value equal to its limit passes.
const LIMIT_SLACK: f64 = 1e-9;

/// Max, min, length-weighted mean and median of `values` with weights `weights`.
fn statistics(values: &[f64], weights: &[f64]) -> (f64, f64, f64, f64) {
    if values.is_empty() {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let total: f64 = weights.iter().sum();
    let mean = if total > 0.0 {
        values.iter().zip(weights).map(|(v, w)| v * w).sum::<f64>() / total
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    };
    // The middle element(s) of the sorted values, found without sorting them all.
    let mut values = values.to_vec();
    let middle = values.len() / 2;
    let odd = values.len() % 2 == 1;
    let (below, &mut at, _) = values.select_nth_unstable_by(middle, f64::total_cmp);
    let median = if odd { at } else { 0.5 * (below.iter().copied().max_by(f64::total_cmp).unwrap_or(at) + at) };
    (max, min, mean.clamp(min, max), median)
}

/// The flute results, the recommended counts (fastest first) and the warnings of §9
/// (`W_MULTI_TOOTH`, `W_TINY_FZ`, `W_NO_RECOMMENDATION`, `W_THRESHOLD_MISSING`).
///
/// # Errors
/// `E_CANCELLED` once `control`'s cancel flag is set (checked per flute count).
pub(crate) fn results(
    job: &Job,
    force: Option<&ForceModel>,
    samples: &[EngagementSample],
    series: &Series,
    statistic: &[bool],
    feed_length: f64,
    control: Control<'_>,
) -> Result<Judged, SolverError> {
    let mut warnings = Vec::new();
    let positions = &series.s;
    let weights: Vec<f64> = positions
        .iter()
        .enumerate()
        .filter(|(i, _)| statistic.get(*i).copied().unwrap_or(false))
        .map(|(i, &s)| s - positions.get(i.wrapping_sub(1)).map_or(s, |&p| p))
        .collect();
    let mut results = Vec::with_capacity(job.flute_counts.len());
    let mut failures = Vec::new();
    for (column, &k) in job.flute_counts.iter().enumerate() {
        control.check()?;
        let (thickness, teeth) = (&series.thickness[column], &series.teeth[column]);
        let values: Vec<f64> = thickness.iter().zip(statistic).filter(|(_, s)| **s).map(|(&h, _)| h).collect();
        let (max, min, mean, median) = statistics(&values, &weights);
        let feed_per_tooth = job.feed_mode.feed_per_tooth(k, job.spindle_rpm);
        let feed = job.feed_mode.feed(k, job.spindle_rpm);
        let time_s = 60.0 * feed_length / feed;
        let representative = match job.representative {
            Representative::Max => max,
            Representative::Mean => mean,
            Representative::Median => median,
        };
        let loads = highest_loads(force, samples, statistic, column);
        let verdict = verdict(job, k, Measured { representative, time_s, feed, loads });
        failures.extend(verdict.failure);
        let multi_tooth_intervals =
            series.runs(|i| statistic.get(i).copied().unwrap_or(false) && teeth.get(i).is_some_and(|n| *n >= 2));
        if !multi_tooth_intervals.is_empty() {
            warnings.push(Warning::new(
                "W_MULTI_TOOTH",
                format!(
                    "k = {k}: two or more teeth cut at once over {} interval(s), first at s = {:.3} mm",
                    multi_tooth_intervals.len(),
                    multi_tooth_intervals.first().map_or(0.0, |i| i[0])
                ),
            ));
        }
        if let (FeedMode::Rate(_), Some(minimum)) = (job.feed_mode, job.min_feed_per_tooth)
            && feed_per_tooth < minimum
        {
            warnings.push(Warning::new(
                "W_TINY_FZ",
                format!("k = {k}: the feed per tooth {feed_per_tooth:.6} mm is below {minimum} mm (rubbing)"),
            ));
        }
        let forces = force_statistics(force, samples, statistic, &weights, column);
        warnings.extend(limit_warnings(job, force, samples, series, statistic, column, k));
        let tooth_passing_hz = tooth_passing(job, force, k, &mut warnings);
        let max_teeth = teeth.iter().zip(statistic).filter(|(_, s)| **s).map(|(&n, _)| n).max().unwrap_or(0);
        results.push(FluteResult {
            flute_count: k,
            feed_per_tooth,
            feed,
            max_thickness: max,
            mean_thickness: mean,
            min_thickness: min,
            median_thickness: median,
            time_s,
            recommended: verdict.recommended,
            thickness_margin: verdict.thickness_margin,
            time_margin_s: verdict.time_margin_s,
            over_limits: verdict.over_limits,
            max_teeth,
            multi_tooth_intervals,
            mean_torque_nm: forces.map(|f| f.0),
            peak_torque_nm: forces.map(|f| f.1),
            mean_power_kw: forces.map(|f| power_kw(f.0, job.spindle_rpm)),
            peak_power_kw: forces.map(|f| power_kw(f.1, job.spindle_rpm)),
            peak_force_n: forces.map(|f| f.2),
            tooth_passing_hz,
        });
    }
    let recommended = recommendation(job, &results, &failures, &mut warnings);
    Ok(Judged { results, recommended, warnings })
}

/// Every flute count's result, the recommended counts (fastest first) and the warnings.
pub(crate) struct Judged {
    pub results: Vec<FluteResult>,
    pub recommended: Vec<u32>,
    pub warnings: Vec<Warning>,
}

/// What one flute count is judged by.
struct Measured {
    /// The representative summed chip thickness, mm.
    representative: f64,
    time_s: f64,
    /// V_f, mm/min.
    feed: f64,
    /// With a force model: the highest phase-mean torque (N·m) and power (kW) of an engaged
    /// sample.
    loads: Option<(f64, f64)>,
}

/// Whether flute count `k` meets the limits (§5.9) with its representative thickness and its
/// time, and the machine's: the margins, the verdict, every limit missed, and why it fails.
struct Verdict {
    thickness_margin: Option<f64>,
    time_margin_s: Option<f64>,
    recommended: bool,
    over_limits: Vec<OverLimit>,
    /// "k = …: thickness … > …, spindle torque … > …" when a limit is missed.
    failure: Option<String>,
}

fn verdict(job: &Job, k: u32, measured: Measured) -> Verdict {
    let Measured { representative, time_s, feed, loads } = measured;
    let thickness_margin = job.thickness_limit.map(|limit| limit - representative);
    let time_margin_s = job.time_limit.map(|limit| limit - time_s);
    let checks = [
        (FluteLimit::Thickness, Some(representative), job.thickness_limit),
        (FluteLimit::Time, Some(time_s), job.time_limit),
        (FluteLimit::SpindleTorque, loads.map(|l| l.0), job.spindle.spindle_torque_nm),
        (FluteLimit::SpindlePower, loads.map(|l| l.1), job.spindle.spindle_power_kw),
        (FluteLimit::SpindleSpeed, Some(job.spindle_rpm), job.machine_speed),
        (FluteLimit::MachineFeed, Some(feed), job.machine_feed),
    ];
    let over_limits: Vec<OverLimit> = checks
        .into_iter()
        .filter_map(|(limit, value, allowed)| {
            let (value, allowed) = (value?, allowed?);
            (value > allowed * (1.0 + LIMIT_SLACK)).then_some(OverLimit { limit, value, allowed })
        })
        .collect();
    let recommended = (job.thickness_limit.is_some() || job.time_limit.is_some()) && over_limits.is_empty();
    let failure = (!over_limits.is_empty())
        .then(|| format!("k = {k}: {}", over_limits.iter().map(OverLimit::describe).collect::<Vec<_>>().join(", ")));
    Verdict { thickness_margin, time_margin_s, recommended, over_limits, failure }
}

/// The highest phase-mean torque and power over the engaged samples of one flute column, as the
/// torque chart draws them and `W_SPINDLE_TORQUE` reports them (with a force model).
fn highest_loads(
    force: Option<&ForceModel>,
    samples: &[EngagementSample],
    statistic: &[bool],
    column: usize,
) -> Option<(f64, f64)> {
    force?;
    let engaged = samples.iter().zip(statistic).filter(|(_, s)| **s).map(|(sample, _)| sample);
    Some(engaged.fold((0.0, 0.0), |(torque, power), sample| {
        (
            torque.max(sample.torque_nm.get(column).copied().unwrap_or(0.0)),
            power.max(sample.power_kw.get(column).copied().unwrap_or(0.0)),
        )
    }))
}

/// The tooth-passing frequency of `k` flutes, with the force model only (so that answers
/// without it stay as they were), and `W_TOOTH_PASSING` near a natural frequency of the tool.
fn tooth_passing(job: &Job, force: Option<&ForceModel>, k: u32, warnings: &mut Vec<Warning>) -> Option<f64> {
    let tooth_passing_hz = force.is_some().then(|| tooth_passing_hz(job.spindle_rpm, k));
    if let Some((natural, axis)) = tooth_passing_hz.and_then(|f| resonance(f, &job.natural)) {
        warnings.push(Warning::new(
            "W_TOOTH_PASSING",
            format!(
                "k = {k}: the tooth-passing frequency {:.1} Hz (N·k/60) lies within {:.0} % of the tool's natural frequency {natural} Hz ({axis}): forced vibration; change the spindle speed",
                tooth_passing_hz.unwrap_or(0.0),
                RESONANCE_BAND * 100.0
            ),
        ));
    }
    tooth_passing_hz
}

/// The recommended flute counts, fastest first (§5.9), with `W_THRESHOLD_MISSING` for a limit
/// not given and `W_NO_RECOMMENDATION` (listing `failures`) when none meets them.
fn recommendation(job: &Job, results: &[FluteResult], failures: &[String], warnings: &mut Vec<Warning>) -> Vec<u32> {
    let mut recommended: Vec<(f64, u32)> =
        results.iter().filter(|r| r.recommended).map(|r| (r.time_s, r.flute_count)).collect();
    recommended.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    match (job.thickness_limit, job.time_limit) {
        (None, None) => warnings.push(Warning::new(
            "W_THRESHOLD_MISSING",
            "neither thickness_limit nor time_limit is given: no flute count is recommended",
        )),
        (None, Some(_)) => warnings.push(Warning::new(
            "W_THRESHOLD_MISSING",
            "thickness_limit is not given: flute counts are recommended on time alone",
        )),
        (Some(_), None) => warnings.push(Warning::new(
            "W_THRESHOLD_MISSING",
            "time_limit_s is not given: flute counts are recommended on chip thickness alone",
        )),
        (Some(_), Some(_)) => {}
    }
    if recommended.is_empty() && (job.thickness_limit.is_some() || job.time_limit.is_some()) {
        warnings.push(Warning::new(
            "W_NO_RECOMMENDATION",
            format!("no flute count satisfies the limits: {}", failures.join("; ")),
        ));
    }
    recommended.into_iter().map(|(_, k)| k).collect()
}

/// Length-weighted mean of the phase-mean torque and the largest phase peak over the engaged
/// samples, N·m, and the largest resultant force, N, for one flute column (with a force model).
fn force_statistics(
    force: Option<&ForceModel>,
    samples: &[EngagementSample],
    statistic: &[bool],
    weights: &[f64],
    column: usize,
) -> Option<(f64, f64, f64)> {
    force?;
    let engaged = || samples.iter().zip(statistic).filter(|(_, s)| **s).map(|(sample, _)| sample);
    let means: Vec<f64> = engaged().map(|s| s.torque_nm.get(column).copied().unwrap_or(0.0)).collect();
    let (_, _, mean, _) = statistics(&means, weights);
    let peak = engaged().filter_map(|s| s.peak_torque_nm.get(column).copied()).fold(0.0, f64::max);
    let force = engaged().filter_map(|s| s.peak_force_n.get(column).copied()).fold(0.0, f64::max);
    Some((mean, peak, force))
}

/// `W_SPINDLE_POWER` and `W_SPINDLE_TORQUE` for one flute column: where the phase-mean power or
/// torque of an engaged sample exceeds the machine's rating.
fn limit_warnings(
    job: &Job,
    force: Option<&ForceModel>,
    samples: &[EngagementSample],
    series: &Series,
    statistic: &[bool],
    column: usize,
    k: u32,
) -> Vec<Warning> {
    let mut warnings = Vec::new();
    if force.is_none() {
        return warnings;
    }
    let column_of = |pick: fn(&EngagementSample) -> &[f64]| -> Vec<f64> {
        samples.iter().map(|s| pick(s).get(column).copied().unwrap_or(0.0)).collect()
    };
    let power = column_of(|s| &s.power_kw);
    let torque = column_of(|s| &s.torque_nm);
    let checks = [
        ("W_SPINDLE_POWER", "power", "kW", job.spindle.spindle_power_kw, &power),
        ("W_SPINDLE_TORQUE", "torque", "N·m", job.spindle.spindle_torque_nm, &torque),
    ];
    for (code, what, unit, limit, values) in checks {
        let Some(limit) = limit else { continue };
        let over = |i: usize| statistic.get(i).copied().unwrap_or(false) && values[i] > limit * (1.0 + LIMIT_SLACK);
        let intervals = series.runs(over);
        if intervals.is_empty() {
            continue;
        }
        let highest = (0..values.len()).filter(|&i| over(i)).map(|i| values[i]).fold(0.0, f64::max);
        warnings.push(Warning::new(
            code,
            format!(
                "k = {k}: the spindle {what} reaches {highest:.3} {unit}, above the machine's {limit} {unit}, over {} interval(s), first at s = {:.3} mm (a feed_plan caps the feed there)",
                intervals.len(),
                intervals.first().map_or(0.0, |i| i[0])
            ),
        ));
    }
    warnings
}

#[cfg(test)]
mod tests {
    use super::statistics;

    #[test]
    fn weighted_statistics() {
        let (max, min, mean, median) = statistics(&[1.0, 3.0, 2.0, 10.0], &[1.0, 1.0, 1.0, 1.0]);
        assert_eq!((max, min, median), (10.0, 1.0, 2.5));
        assert!((mean - 4.0).abs() < 1e-12);
        let (_, _, weighted, odd_median) = statistics(&[1.0, 3.0, 2.0], &[2.0, 1.0, 1.0]);
        assert!((weighted - 7.0 / 4.0).abs() < 1e-12);
        assert_eq!(odd_median, 2.0);
        assert_eq!(statistics(&[], &[]), (0.0, 0.0, 0.0, 0.0));
    }
}
