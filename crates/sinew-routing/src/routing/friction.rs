//! The routing file's friction keys (spec §9, format in [`crate::spec`]): each cable's friction
//! coefficient μ and entry direction, checked, with their defaults. The friction geometry that
//! uses them is `crate::friction`.

use std::collections::HashSet;

use nalgebra::Vector3;

use crate::error::{Result, RoutingError};
use crate::spec::Pattern;

/// The entry direction when a cable gives none: `+z` of its first hole's link.
pub(super) const DEFAULT_ENTRY_DIRECTION: [f64; 3] = [0.0, 0.0, 1.0];

/// A friction coefficient μ checked: finite and ≥ 0 (`cable` empty for the routing-wide one).
pub(super) fn check_coefficient(file: &str, cable: &str, field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(RoutingError::InvalidFrictionCoefficient {
            file: file.to_owned(),
            cable: cable.to_owned(),
            field: field.to_owned(),
            value,
        })
    }
}

/// An entry direction checked (finite, non-zero length) and normalised. Scaled by its largest
/// coordinate first, so that neither a huge nor a tiny (even subnormal) vector over- or
/// underflows on the way to unit length.
pub(super) fn check_entry_direction(
    file: &str,
    cable: &str,
    field: &str,
    direction: [f64; 3],
) -> Result<Vector3<f64>> {
    let largest = direction.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let finite = direction.iter().all(|v| v.is_finite());
    if !(finite && largest > 0.0) {
        return Err(RoutingError::InvalidEntryDirection {
            file: file.to_owned(),
            cable: cable.to_owned(),
            field: field.to_owned(),
            direction,
        });
    }
    Ok((Vector3::from(direction) / largest).normalize())
}

/// Every `[pattern.cable.NAME]` must name a cable the pattern makes (`names`).
pub(super) fn check_pattern_names(
    file: &str,
    pattern: &Pattern,
    names: &HashSet<&str>,
    joints: usize,
) -> Result<()> {
    match pattern.cables.keys().find(|name| !names.contains(name.as_str())) {
        Some(name) => Err(RoutingError::UnknownCable {
            file: file.to_owned(),
            field: format!("pattern.cable.{name}"),
            cable: name.clone(),
            joints,
        }),
        None => Ok(()),
    }
}
