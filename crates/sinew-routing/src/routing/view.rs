//! The serialisable view of a [`Routing`]: what [`Routing::to_json`] and the CLI's `routing`
//! command print, one document for both.

use serde::Serialize;

use super::{Routing, RoutingModel};
use crate::error::{Result, RoutingError};

/// The expanded routing as plain data ([`Routing::view`]): `robot`, `source`, `model`,
/// `youngs_modulus` (Pa), `area` (m²), `tension_limits` (N) and `cables`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct RoutingView<'a> {
    /// The robot the routing was built for.
    pub robot: &'a str,
    /// The file it was read from.
    pub source: &'a str,
    /// How the routing was given.
    pub model: RoutingModel,
    /// Young's modulus `E`, Pa.
    pub youngs_modulus: f64,
    /// Cross-section area `A`, m².
    pub area: f64,
    /// `[f_min, f_max]`, N.
    pub tension_limits: [f64; 2],
    /// The cables, ordered by joint.
    pub cables: Vec<CableView<'a>>,
}

/// A cable of a [`RoutingView`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct CableView<'a> {
    /// Its name.
    pub name: &'a str,
    /// The joint it drives, 0-based.
    pub joint: usize,
    /// Its holes, base first.
    pub holes: Vec<HoleView<'a>>,
    /// Free length from the actuator, m.
    pub free_length: f64,
    /// Routed length at Q = 0, m.
    pub routed_length: f64,
    /// Elastic length `l_c`, m.
    pub elastic_length: f64,
    /// Axial stiffness `E·A / l_c`, N/m.
    pub stiffness: f64,
    /// Least tension, N.
    pub f_min: f64,
    /// Greatest tension, N.
    pub f_max: f64,
}

/// A hole of a [`CableView`]: a point in a link's frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct HoleView<'a> {
    /// URDF link name.
    pub link: &'a str,
    /// Coordinates in the link frame, m.
    pub point: [f64; 3],
}

impl Routing {
    /// The expanded routing as plain data: every cable's holes as link + point in the link
    /// frame, its joint, lengths, stiffness and limits. Serialises as [`Routing`] does.
    pub fn view(&self) -> RoutingView<'_> {
        RoutingView {
            robot: &self.robot,
            source: &self.source,
            model: self.model,
            youngs_modulus: self.youngs_modulus,
            area: self.area,
            tension_limits: self.tension_limits,
            cables: self
                .cables
                .iter()
                .map(|c| CableView {
                    name: &c.name,
                    joint: c.joint,
                    holes: c
                        .holes
                        .iter()
                        .map(|h| HoleView {
                            link: &h.link,
                            point: [h.point.x, h.point.y, h.point.z],
                        })
                        .collect(),
                    free_length: c.free_length,
                    routed_length: c.routed_length,
                    elastic_length: c.elastic_length,
                    stiffness: c.stiffness,
                    f_min: c.tension_limits[0],
                    f_max: c.tension_limits[1],
                })
                .collect(),
        }
    }

    /// The expanded routing ([`Routing::view`]) as pretty-printed JSON, for inspection and
    /// other tools. The same document as `serde::Serialize` for [`Routing`].
    ///
    /// # Errors
    /// [`RoutingError::Serialize`] (not expected: every number is finite).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self)
            .map_err(|e| RoutingError::Serialize { message: e.to_string() })
    }
}

/// [`Routing::view`].
impl Serialize for Routing {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        self.view().serialize(serializer)
    }
}
