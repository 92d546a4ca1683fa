// Deburr clearance on the page: where the ball on its way in or out, or the neck above it along
// the path, runs into the tube or the bored block, so the 3-D view can draw it red and the G-code
// button say why it is off. The workpiece is the one the view draws (docs/spec/deburr.md §1.3: local y
// along the cylinder axis A1, z along the hole axis A2, the hole through the wall on the +z side).
// The service's own checks (E_NO_APPROACH, E_NECK_COLLISION) still decide whether it writes a
// program; this shows where, and catches an approach the page can see is wrong.
import { THREE } from '/plot/scene3d.js';

// Directions on a sphere (a Fibonacci lattice): enough to find a ball inside a wall that is
// thicker than the spacing of the points at the ball's surface.
const SPHERE = Array.from({ length: 96 }, (_, i) => {
  const z = 1 - (2 * i + 1) / 96;
  const r = Math.sqrt(1 - z * z);
  const a = i * Math.PI * (3 - Math.sqrt(5));
  return [r * Math.cos(a), r * Math.sin(a), z];
});

// A deburr request with the tube's and the hole's sizes as radii, whichever way they were given
// (outer_diameter or outer_radius, diameter or radius).
export function inRadii(request) {
  const { workpiece, hole } = request;
  if (!workpiece || !hole) return request;
  const half = (r, d) => r ?? (d === undefined || d === null ? undefined : d / 2);
  const tube = workpiece.kind === 'tube'
    ? { ...workpiece, inner_radius: half(workpiece.inner_radius, workpiece.inner_diameter), outer_radius: half(workpiece.outer_radius, workpiece.outer_diameter) }
    : workpiece;
  return { ...request, workpiece: tube, hole: { ...hole, radius: half(hole.radius, hole.diameter) } };
}

// Machine → workpiece-local coordinates (the inverse of the view's placement).
function localFrame(request) {
  const { workpiece, hole } = request;
  const deg = Math.PI / 180;
  const matrix = new THREE.Matrix4().makeRotationZ((workpiece.arrangement_angle_deg || 0) * deg)
    .multiply(new THREE.Matrix4().makeRotationY((hole.penetration_angle_deg || 0) * deg))
    .setPosition(...workpiece.origin);
  const inverse = matrix.clone().invert();
  const v = new THREE.Vector3();
  return (p) => v.set(p[0], p[1], p[2]).applyMatrix4(inverse).toArray();
}

// Whether the local point [x, y, z] is in the material: the tube's wall (or the block round the
// bore) less the hole, a rounded rectangle seen along z (round: no straight sides; slot: straight
// sides along y) through the +z side.
function materialTest(request) {
  const { workpiece, hole } = request;
  const tube = workpiece.kind === 'tube';
  const inner = tube ? workpiece.inner_radius : workpiece.bore_radius;
  const outer = tube ? workpiece.outer_radius : workpiece.face_distance;
  const along = Array.isArray(hole.centre_distance) ? hole.centre_distance[1] : hole.centre_distance || 0;
  const across = Array.isArray(hole.centre_distance) ? hole.centre_distance[0] : 0;
  const [a, b, r, f] = [across / 2, along / 2, hole.radius, hole.eccentricity || 0];
  return ([x, y, z]) => {
    const axis = Math.hypot(x, z);
    if (axis < inner) return false;
    if (tube ? axis > outer : Math.abs(x) > outer || Math.abs(z) > outer) return false;
    const dx = Math.max(Math.abs(x - f) - a, 0);
    const dy = Math.max(Math.abs(y) - b, 0);
    return !(z > 0 && Math.hypot(dx, dy) < r);
  };
}

// Points every `step` mm along the polyline `points`, with the index of the piece they are on.
function along(points, step) {
  const out = [];
  for (let i = 1; i < points.length; i++) {
    const [p, q] = [points[i - 1], points[i]];
    const length = Math.hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]);
    const count = Math.max(1, Math.ceil(length / step));
    for (let k = 0; k <= count; k++) {
      const t = k / count;
      out.push({ piece: i - 1, at: [0, 1, 2].map((j) => p[j] + (q[j] - p[j]) * t) });
    }
  }
  return out;
}

// Checks the answer's approach and retract (ball) and path (neck) against the workpiece of
// `request`. Returns {approach: [[a, b], ...] stretches of the leads that cut the wall (machine
// coordinates), approachLength (mm), neck: [centre, ...] where the neck or shank meets the wall,
// checked (number of path points looked at), at(centre) → {ball, neck} for any other point}, or
// null when the request has no usable solids.
export function clearance(given, answer) {
  const request = given && inRadii(given);
  const { workpiece, hole } = request || {};
  const sizes = workpiece?.kind === 'tube' ? [workpiece.inner_radius, workpiece.outer_radius] : [workpiece?.bore_radius, workpiece?.face_distance];
  if (![...sizes, hole?.radius].every((v) => Number.isFinite(v) && v > 0) || !workpiece.origin?.every(Number.isFinite)) return null;
  const toLocal = localFrame(request);
  const inside = materialTest(request);
  const tool = answer.tool || {};
  const ball = tool.radius;
  if (!(ball > 0)) return null;
  // The ball cuts the chamfer where the path starts: the ridge sits (W/2)/tan(α/2) inside the
  // ball at most (chamfer width W, least wedge angle α). Only a deeper cut counts as a collision.
  // The check's slack and sampling step are set in mm; an inch answer's lengths are in inches.
  const mm = answer.units === 'inch' ? 1 / 25.4 : 1;
  const s = answer.summary || {};
  const wedge = Math.max(5, s.wedge_angle_min_deg || 90) * Math.PI / 180;
  const width = Math.max(s.width || 0, s.true_width_max || 0);
  const allowance = (width / 2) / Math.tan(wedge / 2) + (request.tolerance || 0) + 0.01 * mm;
  const shell = Math.max(ball - allowance, ball * 0.2);
  const ballInWall = (c) => inside(toLocal(c)) || SPHERE.some((d) => inside(toLocal([c[0] + d[0] * shell, c[1] + d[1] * shell, c[2] + d[2] * shell])));

  const points = answer.points;
  const first = points[0].centre;
  const lastCentre = points[points.length - 1].centre;
  const leads = [
    [...answer.lead_in.map((m) => m.centre), first],
    [lastCentre, ...answer.lead_out.map((m) => m.centre)],
  ].filter((l) => l.length > 1);
  const approach = [];
  const step = Math.max(0.05 * mm, Math.min(0.5 * mm, ball / 4));
  // Runs of consecutive sample points with the ball in the wall, as stretches of the lead.
  for (const lead of leads) {
    let run = null;
    for (const p of along(lead, step)) {
      const hit = ballInWall(p.at);
      if (hit && (!run || run.piece !== p.piece)) {
        run = { piece: p.piece, from: p.at, to: p.at };
        approach.push(run);
      } else if (hit) {
        run.to = p.at;
      } else {
        run = null;
      }
    }
  }
  const stretches = approach.map((r) => [r.from, r.to]);
  const approachLength = stretches.reduce((sum, [a, b]) => sum + Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]), 0);

  // The neck (or, without one, a shank as wide as the ball) straight up from the ball centre,
  // from where it leaves the ball to above the workpiece.
  const neck = Math.min(tool.neck_radius ?? ball, ball) - 0.001 * mm;
  // High enough to clear the workpiece however it is turned (it lies within √2·size of its origin).
  const top = workpiece.origin[2] + 1.5 * Math.max(...sizes, hole.radius * 2);
  const ring = Array.from({ length: 24 }, (_, i) => [Math.cos(i * Math.PI / 12), Math.sin(i * Math.PI / 12)]);
  const neckInWall = (c) => {
    for (let z = Math.sqrt(Math.max(0, ball * ball - neck * neck)); c[2] + z <= top; z += step) {
      if (ring.some(([u, v]) => inside(toLocal([c[0] + u * neck, c[1] + v * neck, c[2] + z])))) return true;
    }
    return false;
  };
  const every = Math.max(1, Math.floor(points.length / 240));
  const looked = points.filter((_, i) => i % every === 0);
  const neckHits = looked.filter((p) => neckInWall(p.centre)).map((p) => p.centre);
  // For the tool at the timeline's move: whether its ball or its neck is in the wall there.
  const at = (c) => ({ ball: ballInWall(c), neck: neckInWall(c) });
  return { approach: stretches, approachLength, neck: neckHits, checked: looked.length, at };
}
