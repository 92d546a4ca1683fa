//! A compact copy of the per-sample values the passes after the sample loop read (the
//! diagnostics' runs of §9, the flute statistics of §5.7), taken while each sample is built:
//! those passes then scan short contiguous arrays instead of the large per-sample records and
//! the small vectors they point to, which at 100 000 samples is most of their cost.

use super::answer::{EngagementSample, SampleFlag};

/// Bits of [`Series::marks`].
pub(crate) const RAPID: u8 = 1;
pub(crate) const BACK_CONTACT: u8 = 2;
pub(crate) const COLLISION: u8 = 4;

/// Per-sample values in sample order; `thickness` and `teeth` per flute column.
#[derive(Debug, Default)]
pub(crate) struct Series {
    pub s: Vec<f64>,
    pub engaged_deg: Vec<f64>,
    pub radial_depth: Vec<f64>,
    pub arc_count: Vec<usize>,
    pub marks: Vec<u8>,
    pub thickness: Vec<Vec<f64>>,
    pub teeth: Vec<Vec<u32>>,
}

impl Series {
    /// Room for `samples` samples of `columns` flute counts.
    pub(crate) fn with_capacity(samples: usize, columns: usize) -> Self {
        Self {
            s: Vec::with_capacity(samples),
            engaged_deg: Vec::with_capacity(samples),
            radial_depth: Vec::with_capacity(samples),
            arc_count: Vec::with_capacity(samples),
            marks: Vec::with_capacity(samples),
            thickness: (0..columns).map(|_| Vec::with_capacity(samples)).collect(),
            teeth: (0..columns).map(|_| Vec::with_capacity(samples)).collect(),
        }
    }

    /// Appends the sample just built.
    pub(crate) fn push(&mut self, sample: &EngagementSample) {
        self.s.push(sample.s);
        self.engaged_deg.push(sample.engaged_deg);
        self.radial_depth.push(sample.radial_depth);
        self.arc_count.push(sample.arcs.len());
        let marks = sample.flags.iter().fold(0, |marks, flag| {
            marks
                | match flag {
                    SampleFlag::Rapid => RAPID,
                    SampleFlag::BackContact => BACK_CONTACT,
                    SampleFlag::Collision => COLLISION,
                    _ => 0,
                }
        });
        self.marks.push(marks);
        for (column, values) in self.thickness.iter_mut().enumerate() {
            values.push(sample.thickness.get(column).copied().unwrap_or(0.0));
        }
        for (column, values) in self.teeth.iter_mut().enumerate() {
            values.push(sample.teeth.get(column).copied().unwrap_or(0));
        }
    }

    /// Whether sample `index` carries mark `mark`.
    pub(crate) fn marked(&self, index: usize, mark: u8) -> bool {
        self.marks.get(index).is_some_and(|marks| marks & mark != 0)
    }

    /// Runs of consecutive samples where `test` holds, as [s_first, s_last].
    pub(crate) fn runs(&self, test: impl Fn(usize) -> bool) -> Vec<[f64; 2]> {
        let mut intervals: Vec<[f64; 2]> = Vec::new();
        let mut open = false;
        for (index, &s) in self.s.iter().enumerate() {
            if test(index) {
                match intervals.last_mut() {
                    Some(last) if open => last[1] = s,
                    _ => intervals.push([s, s]),
                }
                open = true;
            } else {
                open = false;
            }
        }
        intervals
    }
}
