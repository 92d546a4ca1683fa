//! The tool assembly (docs/spec/verify.md §2 Tool assembly): the cutting head, the neck, the
//! shank and the holder as convex solids of revolution about the vertical tool axis, each known
//! by the lowest and highest height above the tip it occupies at a distance from the axis.

use crate::validate::Measure;
use serde::Serialize;

use crate::error::SolverError;
use crate::tool::{Tool, ToolKind};

/// Default stickout, in cutter radii (four diameters).
pub const STICKOUT_RADII: f64 = 8.0;
/// Default flute length, in cutter radii (two diameters).
pub const FLUTE_RADII: f64 = 4.0;
/// Default holder diameter, in shank diameters (a collet nut).
pub const HOLDER_SHANK_DIAMETERS: f64 = 3.0;
/// Default holder length, mm.
pub const HOLDER_LENGTH: f64 = 40.0;

/// Which part of the assembly a solid is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Member {
    /// The cutting head: the only member that removes material.
    Cutter,
    /// The thin neck of a lollipop or back-deburring cutter.
    Neck,
    /// The shank between the cutting part and the holder.
    Shank,
    /// The tool holder.
    Holder,
}

/// The shape of one member.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Shape {
    /// A sphere of radius `radius` whose centre is `radius` above the tip (a lollipop head).
    Sphere,
    /// A cylinder from the tip to `top` whose bottom edge is rounded with `corner` (0 flat,
    /// `radius` ball, between: bull nose).
    Rounded { corner: f64 },
    /// A cylinder from `base` to `top`.
    Cylinder { base: f64 },
}

/// One convex body of the assembly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Body {
    pub member: Member,
    pub shape: Shape,
    pub radius: f64,
    pub top: f64,
}

impl Body {
    /// The lowest height above the tip this solid reaches at distance `d` ≤ `radius` from the
    /// axis: convex and non-decreasing in `d`.
    pub fn lower(&self, d: f64) -> f64 {
        let d = d.min(self.radius);
        match self.shape {
            Shape::Sphere => self.radius - (self.radius * self.radius - d * d).max(0.0).sqrt(),
            Shape::Rounded { corner } => {
                let flat = self.radius - corner;
                if d <= flat {
                    0.0
                } else {
                    let e = d - flat;
                    corner - (corner * corner - e * e).max(0.0).sqrt()
                }
            }
            Shape::Cylinder { base } => base,
        }
    }

    /// The highest height above the tip at distance `d` ≤ `radius`: concave and non-increasing.
    pub fn upper(&self, d: f64) -> f64 {
        match self.shape {
            Shape::Sphere => {
                let d = d.min(self.radius);
                self.radius + (self.radius * self.radius - d * d).max(0.0).sqrt()
            }
            Shape::Rounded { .. } | Shape::Cylinder { .. } => self.top,
        }
    }

    /// Whether the solid's lower surface is a sphere's (a ball end or a lollipop head): its
    /// sweep along a line is a capsule.
    pub fn is_round(&self) -> bool {
        match self.shape {
            Shape::Sphere => true,
            Shape::Rounded { corner } => corner == self.radius,
            Shape::Cylinder { .. } => false,
        }
    }

    /// The lowest height of the solid (at its axis).
    pub fn bottom(&self) -> f64 {
        self.lower(0.0)
    }
}

/// The members of one tool's assembly, cutter first.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Assembly {
    pub bodies: Vec<Body>,
}

impl Assembly {
    /// The assembly of `tool` (validated), with the defaults of docs/spec/verify.md §2; `field`
    /// names the tool in errors (`tools[0]`).
    pub fn new(tool: &Tool, field: &str) -> Result<Self, SolverError> {
        let radius = tool.radius;
        let stickout = tool.stickout.unwrap_or(STICKOUT_RADII * radius);
        let shank_radius = tool.shank_radius.unwrap_or(radius);
        let holder_radius = tool.holder_diameter.map_or(HOLDER_SHANK_DIAMETERS * shank_radius, |d| 0.5 * d);
        let holder_length = tool.holder_length.unwrap_or(HOLDER_LENGTH);
        let corner = match tool.kind {
            ToolKind::Ball => radius,
            ToolKind::Flat => 0.0,
            ToolKind::Bull => tool.corner_radius.unwrap_or(0.0),
        };
        let mut bodies = Vec::with_capacity(4);
        let too_long = |name: &str, length: f64| {
            SolverError::input(
                format!("{field}.{name}"),
                format!(
                    "{name} {} must not exceed the stickout {} (tip to holder face)",
                    Measure::Length.quote(length),
                    Measure::Length.quote(stickout)
                ),
            )
        };
        let neck_base = match (tool.neck_radius, tool.kind) {
            (Some(_), ToolKind::Ball) => {
                bodies.push(Body { member: Member::Cutter, shape: Shape::Sphere, radius, top: 2.0 * radius });
                radius
            }
            _ => {
                let default = if tool.neck_radius.is_some() { radius } else { FLUTE_RADII * radius };
                let flutes = tool.flute_length.unwrap_or(default.min(stickout));
                if flutes > stickout {
                    return Err(too_long("flute_length", flutes));
                }
                bodies.push(Body { member: Member::Cutter, shape: Shape::Rounded { corner }, radius, top: flutes });
                flutes
            }
        };
        let mut shank_base = bodies[0].top;
        if let Some(neck) = tool.neck_radius {
            let top = tool.neck_length.unwrap_or(stickout);
            if top > stickout {
                return Err(too_long("neck_length", top));
            }
            if top <= neck_base {
                return Err(SolverError::input(
                    format!("{field}.neck_length"),
                    format!(
                        "neck_length {} must reach above the cutting head ({} above the tip)",
                        Measure::Length.quote(top),
                        Measure::Length.quote(neck_base)
                    ),
                ));
            }
            bodies.push(Body { member: Member::Neck, shape: Shape::Cylinder { base: neck_base }, radius: neck, top });
            shank_base = top;
        }
        if shank_base < stickout {
            bodies.push(Body {
                member: Member::Shank,
                shape: Shape::Cylinder { base: shank_base },
                radius: shank_radius,
                top: stickout,
            });
        }
        bodies.push(Body {
            member: Member::Holder,
            shape: Shape::Cylinder { base: stickout },
            radius: holder_radius,
            top: stickout + holder_length,
        });
        Ok(Self { bodies })
    }

    /// The cutting head.
    pub fn cutter(&self) -> &Body {
        &self.bodies[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn members_stack_from_the_tip() {
        let mut tool = Tool::new(ToolKind::Ball, 3.0);
        tool.neck_radius = Some(1.5);
        tool.neck_length = Some(12.0);
        tool.stickout = Some(30.0);
        let assembly = Assembly::new(&tool, "tools[0]").unwrap();
        let members: Vec<Member> = assembly.bodies.iter().map(|s| s.member).collect();
        assert_eq!(members, [Member::Cutter, Member::Neck, Member::Shank, Member::Holder]);
        let head = assembly.cutter();
        assert!((head.lower(3.0) - 3.0).abs() < 1e-12 && (head.upper(0.0) - 6.0).abs() < 1e-12);
        assert_eq!(assembly.bodies[3].radius, 9.0);
        let flat = Assembly::new(&Tool::new(ToolKind::Flat, 5.0), "tools[0]").unwrap();
        assert_eq!(flat.cutter().top, 20.0);
        assert_eq!(flat.bodies[1].top, 40.0);
        tool.neck_length = Some(31.0);
        assert_eq!(Assembly::new(&tool, "tools[0]").unwrap_err().field(), Some("tools[0].neck_length"));
    }
}
