//! The feed that holds a target chip thickness along the path (chip-thinning compensation,
//! docs/spec/engagement.md §11 item 3), capped by the machine's feed, as blocks of one feed each.
//!
//! At every sample the feed per tooth that makes the thickest chip equal to h* is
//! f_z' = h*/max sin θ (basis `tooth`) or h*_Σ/(H_k/f_z) (basis `sum`); the feed of the stretch
//! between two samples is the lower of its two ends, and a block keeps the lowest feed of its
//! stretches, so the chip never exceeds the target at any sample. With a force model and the
//! machine's spindle limits the feed is also capped where the phase-mean spindle power or
//! torque would exceed them (docs/spec/engagement.md §11 item 4). Where the tool touches no
//! material the feed is the nominal one, so the tool never approaches the stock faster than it
//! is programmed to cut.

use super::answer::{FeedBlock, FeedLimit, FeedPlan};
use super::arcfeed::ArcFeed;
use super::arcs::peak_thickness_ratio;
use super::contact::Contact;
use super::force::ForceModel;
use super::job::{Job, PlanJob};
use super::request::FeedBasis;
use super::segments::{Route, Station};
use super::teeth::tooth_sum;
use crate::capability::Control;
use crate::error::SolverError;

/// Feed needed at one sample by a cutter of `flutes` teeth, mm/min, and what set it. Out of
/// contact it is the nominal feed: the tool moves through the air at the programmed feed, not at
/// the machine's maximum up to where it touches.
fn needed(
    job: &Job,
    force: Option<&ForceModel>,
    plan: &PlanJob,
    flutes: u32,
    contact: &Contact,
    edge_feed: Option<&ArcFeed>,
) -> (f64, FeedLimit) {
    if contact.arcs.is_empty() {
        let nominal = job.feed_mode.feed(flutes, job.spindle_rpm);
        return if nominal >= plan.max_feed { (plan.max_feed, FeedLimit::Machine) } else { (nominal, FeedLimit::Air) };
    }
    let ratio = match (plan.basis, edge_feed) {
        (FeedBasis::Tooth, None) => peak_thickness_ratio(&contact.arcs),
        (FeedBasis::Sum, None) => tooth_sum(&contact.arcs, flutes).ratio,
        (FeedBasis::Tooth, Some(feed)) => feed.peak_ratio(&contact.arcs),
        (FeedBasis::Sum, Some(feed)) => feed.tooth_sum(&contact.arcs, flutes),
    };
    let per_tooth = if ratio > 1e-12 { plan.target / ratio } else { f64::INFINITY };
    let to_feed = |fz: f64| f64::from(flutes) * job.spindle_rpm * fz;
    let mut best = (to_feed(per_tooth), FeedLimit::Thickness);
    // The spindle: the phase-mean torque grows as f_z^(1−m_c), so the feed per tooth that
    // meets the cap is closed.
    if let (Some(model), Some((torque, by_power))) = (force, job.spindle.torque_cap(job.spindle_rpm)) {
        let integral = model.integral(&contact.arcs, edge_feed, contact.slices.as_ref());
        let feed = to_feed(model.feed_for_torque(torque, integral, flutes));
        if feed < best.0 {
            best = (feed, if by_power { FeedLimit::Power } else { FeedLimit::Torque });
        }
    }
    if best.0 >= plan.max_feed { (plan.max_feed, FeedLimit::Machine) } else { best }
}

/// A stretch between consecutive samples.
#[derive(Debug, Clone, Copy)]
struct Stretch {
    piece: usize,
    from_s: f64,
    to_s: f64,
    /// Feed and what set it; `None` on a rapid.
    feed: Option<(f64, FeedLimit)>,
}

/// Rounds a feed down to whole mm/min (never below 1).
fn whole(feed: f64) -> f64 {
    feed.floor().max(1.0)
}

/// The feed plan for one path and a cutter of `flutes` teeth: the stretches between samples at
/// the feed each needs, grouped into blocks within the tolerance band, short blocks merged, feeds
/// rounded down to whole mm/min.
///
/// # Errors
/// `E_CANCELLED` once `control`'s cancel flag is set (checked per sample).
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan(
    job: &Job,
    force: Option<&ForceModel>,
    plan: &PlanJob,
    flutes: u32,
    route: &Route,
    stations: &[Station],
    contacts: &[Contact],
    control: Control<'_>,
) -> Result<FeedPlan, SolverError> {
    let stretches = stretches(job, force, plan, flutes, route, stations, contacts, control)?;
    let merged = merge_short(group(stretches, plan.tolerance), plan.min_block_length);
    let mut time_s = 0.0;
    let mut range = [f64::INFINITY, 0.0_f64];
    let blocks: Vec<FeedBlock> = merged
        .iter()
        .map(|block| {
            let feed = block.feed.map(|(f, _)| whole(f));
            if let Some(f) = feed {
                time_s += 60.0 * (block.to_s - block.from_s) / f;
                range = [range[0].min(f), range[1].max(f)];
            }
            FeedBlock {
                segment: route.pieces.get(block.piece).map_or(0, |p| p.source),
                from_s: block.from_s,
                to_s: block.to_s,
                feed,
                limited_by: block.feed.map(|(_, limit)| limit),
            }
        })
        .collect();
    if !range[0].is_finite() {
        range = [0.0, 0.0];
    }
    Ok(FeedPlan {
        flute_count: flutes,
        target_thickness: plan.target,
        basis: plan.basis,
        max_feed: plan.max_feed,
        blocks,
        time_s,
        nominal_time_s: 60.0 * route.feed_length / job.feed_mode.feed(flutes, job.spindle_rpm),
        feed_range: range,
    })
}

/// The stretches between consecutive samples, each at the lower of the feeds its two ends need
/// (none on a rapid).
#[allow(clippy::too_many_arguments)]
fn stretches(
    job: &Job,
    force: Option<&ForceModel>,
    plan: &PlanJob,
    flutes: u32,
    route: &Route,
    stations: &[Station],
    contacts: &[Contact],
    control: Control<'_>,
) -> Result<Vec<Stretch>, SolverError> {
    let feeds: Vec<Option<(f64, FeedLimit)>> = stations
        .iter()
        .zip(contacts)
        .map(|(station, contact)| {
            control.check()?;
            let rapid = route.pieces.get(station.piece).is_some_and(|p| p.rapid);
            let edge_feed = if job.arc_feed { ArcFeed::at(route, station, job.radius) } else { None };
            Ok((!rapid).then(|| needed(job, force, plan, flutes, contact, edge_feed.as_ref())))
        })
        .collect::<Result<_, SolverError>>()?;
    let mut stretches = Vec::new();
    for index in 1..stations.len() {
        let (before, here) = (&stations[index - 1], &stations[index]);
        if here.s - before.s <= 0.0 {
            continue;
        }
        let lower = |a: (f64, FeedLimit), b: (f64, FeedLimit)| if a.0 <= b.0 { a } else { b };
        let mut feed = match (feeds[index - 1], feeds[index]) {
            (_, None) => None,
            (None, Some(f)) => Some(f),
            (Some(a), Some(b)) => Some(lower(a, b)),
        };
        // A stretch through the air that ends where the tool touches (tangent to the stock, no
        // arc yet) or starts where it leaves takes the cutting feed of its neighbour: no move
        // reaches the stock faster than the cut it leads into.
        let in_air = contacts[index - 1].arcs.is_empty() && contacts[index].arcs.is_empty();
        if let Some(air) = feed.filter(|_| in_air) {
            let touching = |i: Option<usize>| -> Option<(f64, FeedLimit)> {
                let i = i?;
                let contact = contacts.get(i).is_some_and(|c| !c.arcs.is_empty());
                feeds.get(i).copied().flatten().filter(|_| contact)
            };
            feed = Some(
                [touching(index.checked_sub(2)), touching(Some(index + 1))].into_iter().flatten().fold(air, lower),
            );
        }
        stretches.push(Stretch { piece: here.piece, from_s: before.s, to_s: here.s, feed });
    }
    Ok(stretches)
}

/// Stretches of one piece whose feeds lie within `tolerance` of the lowest grouped into one block
/// at that lowest feed; each block with the highest feed it took in.
fn group(stretches: Vec<Stretch>, tolerance: f64) -> Vec<(Stretch, f64)> {
    // Group stretches of one piece whose feeds lie within the tolerance band.
    let mut blocks: Vec<(Stretch, f64)> = Vec::new();
    for stretch in stretches {
        if let Some((block, highest)) = blocks.last_mut()
            && block.piece == stretch.piece
        {
            match (block.feed, stretch.feed) {
                (None, None) => {
                    block.to_s = stretch.to_s;
                    continue;
                }
                (Some(low), Some(feed)) => {
                    let new_low = if feed.0 < low.0 { feed } else { low };
                    let new_high = highest.max(feed.0);
                    if new_high <= new_low.0 * (1.0 + tolerance) {
                        block.feed = Some(new_low);
                        block.to_s = stretch.to_s;
                        *highest = new_high;
                        continue;
                    }
                }
                _ => {}
            }
        }
        let high = stretch.feed.map_or(0.0, |f| f.0);
        blocks.push((stretch, high));
    }
    blocks
}

/// Blocks shorter than `min_block_length` merged into their neighbour on the same piece, at the
/// lower feed.
fn merge_short(blocks: Vec<(Stretch, f64)>, min_block_length: f64) -> Vec<Stretch> {
    // Merge blocks shorter than the minimum into their neighbour, at the lower feed.
    let mut merged: Vec<Stretch> = Vec::with_capacity(blocks.len());
    for (block, _) in blocks {
        if let Some(last) = merged.last_mut()
            && last.piece == block.piece
            && last.feed.is_some() == block.feed.is_some()
            && (last.to_s - last.from_s < min_block_length || block.to_s - block.from_s < min_block_length)
        {
            last.to_s = block.to_s;
            last.feed = match (last.feed, block.feed) {
                (Some(a), Some(b)) => Some(if a.0 <= b.0 { a } else { b }),
                _ => None,
            };
            continue;
        }
        merged.push(block);
    }
    merged
}
