//! Where the tool touches the stock at every sample of a path (docs/spec/engagement.md §5.3): the
//! exact engine's boundary test (§5.3.3) with the plunge check where a cut begins and a rounded
//! end's height sections (§11 item 5), or the dots engine's removal on its grid (§5.3.2) with the
//! contact dots for the scatter plot.

use super::answer::GridInfo;
use super::arcfeed::ArcFeed;
use super::arcs::Arc;
use super::dots::{Contacts, DotGrid};
use super::exact::ExactEngine;
use super::heights::{Bands, MAX_SECTIONS};
use super::job::{CandidateJob, Job, grid_extent};
use super::segments::{Route, Station};
use crate::capability::Control;
use crate::error::SolverError;

/// Arcs shared between consecutive contacts that found the same ones.
pub(crate) type SharedArcs = std::sync::Arc<[Arc]>;

/// What an engine found at one station.
#[derive(Debug, Clone, Default)]
pub(crate) struct Contact {
    /// Shared with the previous contact when equal to the bit (most samples along a straight
    /// cut): one allocation per change of engagement instead of one per sample.
    pub arcs: SharedArcs,
    pub plunge: bool,
    pub collision: bool,
    /// With a rounded end's force model and the exact engine: what the end's sections engage,
    /// each height its own arcs.
    pub slices: Option<Bands>,
}

/// The dots engine's extras.
pub(super) struct DotsOutput {
    pub grid: Option<GridInfo>,
    pub scatter: Vec<[f64; 2]>,
}

/// Whether two arc lists are the same to the bit.
pub(super) fn same_arcs(first: &[Arc], second: &[Arc]) -> bool {
    first.len() == second.len()
        && first
            .iter()
            .zip(second)
            .all(|(a, b)| a.from.to_bits() == b.from.to_bits() && a.to.to_bits() == b.to.to_bits())
}

/// `arcs` as a contact's, shared with `previous`'s when they are the same.
fn share_arcs(previous: Option<&Contact>, arcs: &[Arc]) -> SharedArcs {
    match previous {
        Some(previous) if same_arcs(&previous.arcs, arcs) => SharedArcs::clone(&previous.arcs),
        _ => SharedArcs::from(arcs),
    }
}

fn first_cut(route: &Route, stations: &[Station], index: usize) -> bool {
    let Some(station) = stations.get(index) else {
        return false;
    };
    let rapid = |s: &Station| route.pieces.get(s.piece).is_some_and(|p| p.rapid);
    !rapid(station) && (index == 0 || stations.get(index - 1).is_some_and(rapid))
}

pub(super) fn run_exact(
    job: &Job,
    candidate: &CandidateJob,
    stations: &[Station],
    control: Control<'_>,
) -> Result<Vec<Contact>, SolverError> {
    let route = &candidate.route;
    let mut engine = ExactEngine::default();
    // The height bands of a rounded end, each with its own section's radius (docs/spec/engagement.md §11
    // item 5); their own engine, whose work limit grows with their number.
    let rounded = candidate.force.as_ref().filter(|model| model.rounded());
    let mut section_engine = ExactEngine::with_limit(super::exact::MAX_TESTS.saturating_mul(MAX_SECTIONS as u64));
    let mut contacts = Vec::with_capacity(stations.len());
    for (index, station) in stations.iter().enumerate() {
        control.check()?;
        control.report(index, stations.len());
        let rapid = route.pieces.get(station.piece).is_some_and(|p| p.rapid);
        let arcs = share_arcs(contacts.last(), engine.arcs_in_place(route, &job.region, job.radius, station)?);
        let mut contact = Contact::default();
        if rapid {
            contact.collision = !arcs.is_empty();
        } else {
            if first_cut(route, stations, index) {
                // Contact where the cut begins (the piece's start): the tool enters in material.
                let start = Station {
                    local: 0.0,
                    s: station.s - station.local,
                    centre: route.pieces.get(station.piece).map_or(station.centre, |p| p.shape.start_point()),
                    ..*station
                };
                contact.plunge = !engine.arcs_in_place(route, &job.region, job.radius, &start)?.is_empty();
            }
            if let Some(model) = rounded {
                contact.slices = model.bands(
                    &arcs,
                    |radius| section_engine.arcs(route, &job.region, radius, station),
                    |radius| if job.arc_feed { ArcFeed::at(route, station, radius) } else { None },
                )?;
            }
            contact.arcs = arcs;
        }
        contacts.push(contact);
    }
    Ok(contacts)
}

pub(super) fn run_dots(
    job: &Job,
    route: &Route,
    stations: &[Station],
    cell: f64,
    control: Control<'_>,
) -> Result<(Vec<Contact>, DotsOutput), SolverError> {
    let radius = job.radius;
    let extent =
        job.region.bbox().and_then(|stock_box| grid_extent(route, stock_box, job.region.anchor(), radius, cell));
    let Some((origin, width, height)) = extent else {
        return Ok((vec![Contact::default(); stations.len()], DotsOutput { grid: None, scatter: Vec::new() }));
    };
    // The request check bounds width·height by MAX_GRID_DOTS.
    let mut grid = DotGrid::new(&job.region, origin, cell, width as usize, height as usize);
    let (width, height) = grid.size();
    let info = GridInfo { cell, origin: [grid.origin().x, grid.origin().y], width, height, bytes: grid.bytes() };
    let mut contacts = Vec::with_capacity(stations.len());
    let mut scatter = Vec::new();
    let mut buffer = Contacts { keep_angles: job.contact_dots, ..Contacts::default() };
    let mut previous: Option<&Station> = None;
    for (index, station) in stations.iter().enumerate() {
        control.check()?;
        control.report(index, stations.len());
        let rapid = route.pieces.get(station.piece).is_some_and(|p| p.rapid);
        let mut contact = Contact::default();
        if rapid {
            contact.collision = grid.any_inside(station.centre, radius);
            previous = None;
        } else {
            let step = previous.map_or(job.step, |p| station.s - p.s);
            buffer.clear();
            grid.remove(station.centre, previous.map(|p| p.centre), radius, &mut |dot| {
                buffer.record(dot, station, radius, step, cell)
            });
            contact.plunge = previous.is_none() && buffer.touched();
            if job.contact_dots {
                let mut bins = [0_u64; 6];
                for angle in &buffer.angles {
                    let bin = (angle.floor() + 180.0).clamp(0.0, 359.0) as usize;
                    bins[bin / 64] |= 1 << (bin % 64);
                }
                for bin in 0..360 {
                    if bins[bin / 64] & (1 << (bin % 64)) != 0 {
                        scatter.push([station.s, bin as f64 - 180.0 + 0.5]);
                    }
                }
            }
            contact.arcs = share_arcs(contacts.last(), &buffer.arcs(radius, cell, step));
            previous = Some(station);
        }
        contacts.push(contact);
    }
    Ok((contacts, DotsOutput { grid: Some(info), scatter }))
}
