//! STL stock meshes (docs/spec/predict.md §1.2 I1): parsing ASCII and binary STL from bytes, the
//! closedness check, and point membership by the parity of a vertical ray, with an xy bin grid so
//! each query only looks at nearby triangles.

use crate::error::ErrorCode;
use std::collections::HashMap;

use crate::error::SolverError;
use crate::geometry::Vec3;
use crate::validate::MAX_COORDINATE;

/// Most triangles accepted in a stock mesh.
pub const MAX_TRIANGLES: usize = 2_000_000;
/// Most bins of the xy grid.
const MAX_BINS: usize = 1 << 20;

/// A closed triangle mesh ready for membership queries.
#[derive(Debug, Clone)]
pub(crate) struct Mesh {
    triangles: Vec<Triangle>,
    origin: [f64; 2],
    bin_size: f64,
    bins_x: usize,
    bins_y: usize,
    /// Triangle indices per bin (CSR layout).
    bin_start: Vec<u32>,
    bin_items: Vec<u32>,
    pub(crate) lo: Vec3,
    pub(crate) hi: Vec3,
}

#[derive(Debug, Clone, Copy)]
struct Triangle {
    /// Vertices ordered counter-clockwise in xy.
    p: [Vec3; 3],
    /// No xy area: it never owns a vertical ray (but still bounds boxes).
    vertical: bool,
    lo: Vec3,
    hi: Vec3,
}

fn mesh_error(code: ErrorCode, message: impl Into<String>) -> SolverError {
    SolverError::new(code, message).at("stock")
}

/// Reads an STL file (ASCII or binary) whose coordinates are in `units` into triangles in mm.
///
/// # Errors
/// As [`parse`]; `E_MESH_FORMAT` for a coordinate beyond the range once in mm.
pub(crate) fn parse_in(bytes: &[u8], units: crate::units::Units) -> Result<Vec<[Vec3; 3]>, SolverError> {
    let mut triangles = parse(bytes)?;
    let Some(scaling) = units.into_mm() else { return Ok(triangles) };
    for (index, triangle) in triangles.iter_mut().enumerate() {
        for vertex in triangle.iter_mut() {
            crate::units::Scale::scale(vertex, scaling);
            if !vertex.iter().all(|c| in_range(*c)) {
                return Err(mesh_error(
                    ErrorCode::MeshFormat,
                    format!("triangle {index} has a coordinate beyond ±{MAX_COORDINATE} mm once in mm"),
                ));
            }
        }
    }
    Ok(triangles)
}

/// Reads an STL file (ASCII or binary) into triangles.
pub(crate) fn parse(bytes: &[u8]) -> Result<Vec<[Vec3; 3]>, SolverError> {
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if count.checked_mul(50).and_then(|n| n.checked_add(84)) == Some(bytes.len()) {
            return parse_binary(bytes, count);
        }
    }
    let text = std::str::from_utf8(bytes).map_err(|_| {
        mesh_error(
            ErrorCode::MeshFormat,
            "the stock file is neither binary STL (size does not match its triangle count) nor ASCII STL",
        )
    })?;
    if !text.trim_start().starts_with("solid") {
        return Err(mesh_error(
            ErrorCode::MeshFormat,
            "the stock file is neither binary STL (size does not match its triangle count) nor ASCII STL (no 'solid' header)",
        ));
    }
    parse_ascii(text)
}

fn parse_binary(bytes: &[u8], count: usize) -> Result<Vec<[Vec3; 3]>, SolverError> {
    if count > MAX_TRIANGLES {
        return Err(mesh_error(
            ErrorCode::MeshTooLarge,
            format!("the stock mesh has {count} triangles; the limit is {MAX_TRIANGLES}"),
        ));
    }
    let mut triangles = Vec::with_capacity(count);
    for record in bytes[84..].chunks_exact(50) {
        let value = |offset: usize| {
            f64::from(f32::from_le_bytes([record[offset], record[offset + 1], record[offset + 2], record[offset + 3]]))
        };
        let vertex = |k: usize| Vec3::new(value(12 + 12 * k), value(16 + 12 * k), value(20 + 12 * k));
        let triangle = [vertex(0), vertex(1), vertex(2)];
        if triangle.iter().any(|v| !v.iter().all(|c| in_range(*c))) {
            return Err(mesh_error(
                ErrorCode::MeshFormat,
                format!(
                    "triangle {} has a coordinate that is not a finite number within ±{MAX_COORDINATE} mm",
                    triangles.len()
                ),
            ));
        }
        triangles.push(triangle);
    }
    Ok(triangles)
}

/// Whether a vertex coordinate lies in the one range of every request's geometry.
fn in_range(value: f64) -> bool {
    value.is_finite() && value.abs() <= MAX_COORDINATE
}

fn parse_ascii(text: &str) -> Result<Vec<[Vec3; 3]>, SolverError> {
    let mut triangles = Vec::new();
    let mut corners: Vec<Vec3> = Vec::with_capacity(3);
    for (index, line) in text.lines().enumerate() {
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("vertex") => {
                let mut coordinates = [0.0; 3];
                for coordinate in &mut coordinates {
                    *coordinate =
                        tokens.next().and_then(|t| t.parse::<f64>().ok()).filter(|v| in_range(*v)).ok_or_else(
                            || {
                                mesh_error(
                                    ErrorCode::MeshFormat,
                                    format!(
                                        "STL line {}: a vertex needs three finite numbers within ±{MAX_COORDINATE} mm",
                                        index + 1
                                    ),
                                )
                            },
                        )?;
                }
                corners.push(Vec3::new(coordinates[0], coordinates[1], coordinates[2]));
            }
            Some("endloop") => {
                if corners.len() != 3 {
                    return Err(mesh_error(
                        ErrorCode::MeshFormat,
                        format!("STL line {}: a facet has {} vertices, not 3", index + 1, corners.len()),
                    ));
                }
                triangles.push([corners[0], corners[1], corners[2]]);
                corners.clear();
                if triangles.len() > MAX_TRIANGLES {
                    return Err(mesh_error(
                        ErrorCode::MeshTooLarge,
                        format!("the stock mesh has more than {MAX_TRIANGLES} triangles, the limit"),
                    ));
                }
            }
            _ => {}
        }
    }
    Ok(triangles)
}

/// Checks that the triangles form closed, consistently oriented surfaces: after merging equal
/// vertices every edge is used exactly twice, once in each direction.
pub(crate) fn check_closed(triangles: &[[Vec3; 3]]) -> Result<(), SolverError> {
    if triangles.is_empty() {
        return Err(mesh_error(ErrorCode::MeshEmpty, "the stock mesh has no triangles"));
    }
    let mut vertex_ids: HashMap<[u64; 3], u32> = HashMap::new();
    let mut id = |v: &Vec3| -> u32 {
        let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let next = vertex_ids.len() as u32;
        *vertex_ids.entry(key).or_insert(next)
    };
    // Per undirected edge: (uses, forward uses − backward uses).
    let mut edges: HashMap<(u32, u32), (u32, i32)> = HashMap::new();
    for triangle in triangles {
        let ids = [id(&triangle[0]), id(&triangle[1]), id(&triangle[2])];
        if ids[0] == ids[1] || ids[1] == ids[2] || ids[2] == ids[0] {
            continue;
        }
        for k in 0..3 {
            let (from, to) = (ids[k], ids[(k + 1) % 3]);
            let key = (from.min(to), from.max(to));
            let entry = edges.entry(key).or_insert((0, 0));
            entry.0 += 1;
            entry.1 += if from < to { 1 } else { -1 };
        }
    }
    let open = edges.values().filter(|(uses, _)| *uses == 1).count();
    let bad = edges.values().filter(|(uses, balance)| *uses > 2 || (*uses == 2 && *balance != 0)).count();
    if open > 0 {
        return Err(mesh_error(
            ErrorCode::MeshNotClosed,
            format!("the stock mesh is not closed: {open} edges belong to only one triangle"),
        ));
    }
    if bad > 0 {
        return Err(mesh_error(
            ErrorCode::MeshNotClosed,
            format!(
                "the stock mesh is not a closed surface: {bad} edges are shared by more than two triangles or by two with the same orientation"
            ),
        ));
    }
    Ok(())
}

/// The signed volume the triangles enclose, mm³: positive when their normals (by the right-hand
/// rule) point outward, negative for a surface turned inside out.
pub(crate) fn signed_volume(triangles: &[[Vec3; 3]]) -> f64 {
    triangles.iter().map(|[a, b, c]| a.dot(&b.cross(c))).sum::<f64>() / 6.0
}

/// Orientation of (p - a) relative to the edge a→b in xy, computed the same way for both
/// directions of an edge so neighbouring triangles agree exactly.
#[inline]
fn edge_function(a: &Vec3, b: &Vec3, px: f64, py: f64) -> f64 {
    let forward = (a.x, a.y) < (b.x, b.y);
    let (u, v) = if forward { (a, b) } else { (b, a) };
    let value = (v.x - u.x) * (py - u.y) - (v.y - u.y) * (px - u.x);
    if forward { value } else { -value }
}

/// Fill rule: a point on an edge belongs to the triangle that sees the edge in this direction.
#[inline]
fn owns_edge(a: &Vec3, b: &Vec3) -> bool {
    b.y < a.y || (b.y == a.y && b.x < a.x)
}

impl Mesh {
    pub(crate) fn new(triangles: &[[Vec3; 3]]) -> Self {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        let mut prepared = Vec::with_capacity(triangles.len());
        for t in triangles {
            let [a, b, c] = *t;
            let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
            let t_lo = a.inf(&b).inf(&c);
            let t_hi = a.sup(&b).sup(&c);
            lo = lo.inf(&t_lo);
            hi = hi.sup(&t_hi);
            let p = if area >= 0.0 { [a, b, c] } else { [a, c, b] };
            prepared.push(Triangle { p, vertical: area == 0.0, lo: t_lo, hi: t_hi });
        }
        let width = (hi.x - lo.x).max(1e-9);
        let height = (hi.y - lo.y).max(1e-9);
        let target = prepared.len().clamp(1, MAX_BINS) as f64;
        let bin_size = (width * height / target).sqrt().max(width / 1024.0).max(height / 1024.0);
        let bins_x = ((width / bin_size).ceil() as usize).max(1);
        let bins_y = ((height / bin_size).ceil() as usize).max(1);
        let mut counts = vec![0u32; bins_x * bins_y + 1];
        let range = |t: &Triangle| {
            let cell = |v: f64, origin: f64, count: usize| {
                (((v - origin) / bin_size).floor().max(0.0) as usize).min(count - 1)
            };
            (
                cell(t.lo.x, lo.x, bins_x),
                cell(t.hi.x, lo.x, bins_x),
                cell(t.lo.y, lo.y, bins_y),
                cell(t.hi.y, lo.y, bins_y),
            )
        };
        for t in &prepared {
            let (x0, x1, y0, y1) = range(t);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    counts[y * bins_x + x + 1] += 1;
                }
            }
        }
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[counts.len() - 1] as usize];
        for (index, t) in prepared.iter().enumerate() {
            let (x0, x1, y0, y1) = range(t);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let slot = &mut fill[y * bins_x + x];
                    items[*slot as usize] = index as u32;
                    *slot += 1;
                }
            }
        }
        Self {
            triangles: prepared,
            origin: [lo.x, lo.y],
            bin_size,
            bins_x,
            bins_y,
            bin_start: counts,
            bin_items: items,
            lo,
            hi,
        }
    }

    fn bin(&self, x: f64, y: f64) -> Option<usize> {
        let bx = ((x - self.origin[0]) / self.bin_size).floor();
        let by = ((y - self.origin[1]) / self.bin_size).floor();
        (bx >= 0.0 && by >= 0.0 && (bx as usize) < self.bins_x && (by as usize) < self.bins_y)
            .then(|| by as usize * self.bins_x + bx as usize)
    }

    fn bin_triangles(&self, bin: usize) -> &[u32] {
        &self.bin_items[self.bin_start[bin] as usize..self.bin_start[bin + 1] as usize]
    }

    /// The height at which triangle `t` owns the vertical line through `(x, y)`, if it does
    /// (the fill rule gives a point on a shared edge or vertex to exactly one triangle).
    fn crossing(t: &Triangle, x: f64, y: f64) -> Option<f64> {
        if t.vertical || x < t.lo.x || x > t.hi.x || y < t.lo.y || y > t.hi.y {
            return None;
        }
        let [a, b, c] = &t.p;
        let w0 = edge_function(b, c, x, y);
        let w1 = edge_function(c, a, x, y);
        let w2 = edge_function(a, b, x, y);
        let covered = |w: f64, u: &Vec3, v: &Vec3| w > 0.0 || (w == 0.0 && owns_edge(u, v));
        if !(covered(w0, b, c) && covered(w1, c, a) && covered(w2, a, b)) {
            return None;
        }
        let sum = w0 + w1 + w2;
        (sum > 0.0).then(|| (w0 * a.z + w1 * b.z + w2 * c.z) / sum)
    }

    /// Whether `q` is inside the solid: the upward vertical ray from `q` crosses the surface an
    /// odd number of times, counting only crossings more than `margin` above `q`.
    pub(crate) fn contains(&self, q: &Vec3, margin: f64) -> bool {
        let Some(bin) = self.bin(q.x, q.y) else {
            return false;
        };
        if q.z >= self.hi.z {
            return false;
        }
        let mut inside = false;
        for &index in self.bin_triangles(bin) {
            let t = &self.triangles[index as usize];
            if t.hi.z <= q.z {
                continue;
            }
            if let Some(z) = Self::crossing(t, q.x, q.y)
                && z > q.z + margin
            {
                inside = !inside;
            }
        }
        inside
    }

    /// The heights at which the vertical line through `(x, y)` crosses the surface, sorted
    /// (into `heights`, cleared first): on a closed surface, pairs of them bound the solid.
    pub(crate) fn crossings(&self, x: f64, y: f64, heights: &mut Vec<f64>) {
        heights.clear();
        let Some(bin) = self.bin(x, y) else {
            return;
        };
        for &index in self.bin_triangles(bin) {
            heights.extend(Self::crossing(&self.triangles[index as usize], x, y));
        }
        heights.sort_by(f64::total_cmp);
    }

    /// Whether any triangle's box meets the box `[lo, hi]`; if not, the box lies entirely inside
    /// or entirely outside the solid.
    pub(crate) fn touches(&self, lo: &Vec3, hi: &Vec3) -> bool {
        if hi.x < self.lo.x || lo.x > self.hi.x || hi.y < self.lo.y || lo.y > self.hi.y {
            return false;
        }
        let clamp_bin = |v: f64, origin: f64, count: usize| {
            (((v - origin) / self.bin_size).floor().max(0.0) as usize).min(count - 1)
        };
        let (x0, x1) = (clamp_bin(lo.x, self.origin[0], self.bins_x), clamp_bin(hi.x, self.origin[0], self.bins_x));
        let (y0, y1) = (clamp_bin(lo.y, self.origin[1], self.bins_y), clamp_bin(hi.y, self.origin[1], self.bins_y));
        for y in y0..=y1 {
            for x in x0..=x1 {
                for &index in self.bin_triangles(y * self.bins_x + x) {
                    let t = &self.triangles[index as usize];
                    if t.lo.x <= hi.x
                        && t.hi.x >= lo.x
                        && t.lo.y <= hi.y
                        && t.hi.y >= lo.y
                        && t.lo.z <= hi.z
                        && t.hi.z >= lo.z
                    {
                        return true;
                    }
                }
            }
        }
        false
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A closed box as 12 triangles, outward normals.
    pub(crate) fn box_triangles(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 3]> {
        let corner = |i: usize| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut triangles = Vec::new();
        for q in quads {
            triangles.push([corner(q[0]), corner(q[1]), corner(q[2])]);
            triangles.push([corner(q[0]), corner(q[2]), corner(q[3])]);
        }
        triangles
    }

    pub(crate) fn binary_stl(triangles: &[[Vec3; 3]]) -> Vec<u8> {
        let mut bytes = vec![0u8; 80];
        bytes.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
        for t in triangles {
            bytes.extend_from_slice(&[0u8; 12]);
            for v in t {
                for c in v.iter() {
                    bytes.extend_from_slice(&(*c as f32).to_le_bytes());
                }
            }
            bytes.extend_from_slice(&[0u8; 2]);
        }
        bytes
    }

    #[test]
    fn binary_and_ascii_round_trip_and_membership() {
        let triangles = box_triangles(Vec3::new(0.0, 0.0, 0.0), Vec3::new(4.0, 3.0, 2.0));
        let binary = parse(&binary_stl(&triangles)).unwrap();
        assert_eq!(binary.len(), 12);
        let mut ascii = String::from("solid cube\n");
        for t in &triangles {
            ascii.push_str("facet normal 0 0 0\n outer loop\n");
            for v in t {
                ascii.push_str(&format!("  vertex {} {} {}\n", v.x, v.y, v.z));
            }
            ascii.push_str(" endloop\nendfacet\n");
        }
        ascii.push_str("endsolid cube\n");
        let from_text = parse(ascii.as_bytes()).unwrap();
        assert_eq!(from_text, triangles);
        check_closed(&from_text).unwrap();
        let mesh = Mesh::new(&from_text);
        // Points on the diagonals of the faces' triangulation and on edges must be exact.
        for (q, inside) in [
            (Vec3::new(1.0, 1.0, 1.0), true),
            (Vec3::new(2.0, 1.5, 1.9), true),
            (Vec3::new(3.0, 2.25, 0.5), true),
            (Vec3::new(0.0, 0.0, 1.0), false),
            (Vec3::new(2.0, 1.5, 2.1), false),
            (Vec3::new(5.0, 1.0, 1.0), false),
            (Vec3::new(2.0, 1.5, -0.1), false),
        ] {
            assert_eq!(mesh.contains(&q, 0.0), inside, "{q:?}");
        }
        assert!(mesh.touches(&Vec3::new(3.9, 1.0, 1.0), &Vec3::new(4.1, 1.1, 1.1)));
        assert!(!mesh.touches(&Vec3::new(1.0, 1.0, 1.0), &Vec3::new(1.1, 1.1, 1.1)));
    }

    #[test]
    fn open_and_broken_meshes_are_refused() {
        let mut triangles = box_triangles(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0));
        triangles.pop();
        assert_eq!(check_closed(&triangles).unwrap_err().code(), ErrorCode::MeshNotClosed);
        let mut flipped = box_triangles(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0));
        flipped[0].swap(1, 2);
        assert_eq!(check_closed(&flipped).unwrap_err().code(), ErrorCode::MeshNotClosed);
        assert_eq!(check_closed(&[]).unwrap_err().code(), ErrorCode::MeshEmpty);
        assert_eq!(parse(b"not an stl").unwrap_err().code(), ErrorCode::MeshFormat);
        assert_eq!(
            parse(b"solid x\nfacet\nouter loop\nvertex 1 2\nendloop\n").unwrap_err().code(),
            ErrorCode::MeshFormat
        );
    }
}
