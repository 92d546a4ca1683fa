//! The axial depth of each candidate path (docs/spec/engagement.md §11 item 4): given, or the
//! stock top less the path's Z (`cut_z`, a G-code path's own), checked against the flute length.

use crate::error::{SolverError, Warning};
use crate::tool::Tool;

/// The one Z level of a G-code path's XY feed moves, with its field, for a_p from the stock
/// height (only when no explicit a_p wins: `wanted`); several levels give `W_AXIAL_DEPTH` and
/// none.
pub(super) fn program_level(
    levels: &[(f64, usize)],
    field: &str,
    wanted: bool,
    warnings: &mut Vec<Warning>,
) -> Option<(f64, String)> {
    let (&(first, line), rest) = levels.split_first()?;
    let other = rest.iter().find(|(z, _)| (z - first).abs() > 1e-6);
    match other {
        None => Some((first, format!("{field} (Z of its feed moves, line {line})"))),
        Some((z, other_line)) => {
            if wanted {
                warnings.push(Warning::new(
                    "W_AXIAL_DEPTH",
                    format!(
                        "the program's XY feed moves run at several Z levels (Z {first} at line {line}, Z {z} at line {other_line}): no a_p from the stock height; the 2-D model takes one level per path, so give axial_depth or cut_z, or each level as its own entry of paths"
                    ),
                ));
            }
            None
        }
    }
}

/// a_p of one path and the Z it runs at when a_p came from it: the explicit axial depth
/// (`explicit`, with its field) wins; else `top` − the path's Z (`height`, with its field),
/// 0 at or above the top. Both warn where they disagree; an a_p beyond the tool's flute length
/// is refused at the field that set it.
pub(super) fn path_depth(
    explicit: Option<(f64, String)>,
    height: Option<(f64, String)>,
    top: f64,
    tool: &Tool,
    warnings: &mut Vec<Warning>,
) -> Result<(Option<f64>, Option<f64>), SolverError> {
    let reach = |depth: f64, field: &str, how: &str| -> Result<(), SolverError> {
        match tool.flute_length {
            Some(length) if depth > length => Err(SolverError::input(
                field,
                format!(
                    "{how} a_p = {depth} mm, more than the tool's flute_length {length} mm: the shank would cut (check the path's Z and the stock top)"
                ),
            )),
            _ => Ok(()),
        }
    };
    if let Some((depth, field)) = explicit {
        if let Some((z, z_field)) = &height
            && ((top - z).max(0.0) - depth).abs() > 1e-9
        {
            warnings.push(Warning::new(
                "W_AXIAL_DEPTH",
                format!(
                    "{field} = {depth} mm is used; the path's Z {z} ({z_field}) under the stock top {top} would give a_p = {} mm",
                    (top - z).max(0.0)
                ),
            ));
        }
        reach(depth, &field, &format!("{field} gives"))?;
        return Ok((Some(depth), None));
    }
    let Some((z, field)) = height else {
        return Ok((None, None));
    };
    let depth = top - z;
    if depth <= 0.0 {
        warnings.push(Warning::new(
            "W_AXIAL_DEPTH",
            format!(
                "the tool tip runs at Z {z} ({field}), at or above the stock top {top}: a_p = 0, the path cuts no chip (torque, power and removal rate are 0)"
            ),
        ));
        return Ok((Some(0.0), Some(z)));
    }
    let field_name = field.split(' ').next().unwrap_or(&field).to_owned();
    reach(depth, &field_name, &format!("the stock top {top} less the path's Z {z} ({field}) gives"))?;
    Ok((Some(depth), Some(z)))
}
