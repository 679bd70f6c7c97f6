//! The robot description file, `robot.toml`: the URDF plus what URDF does not carry.
//!
//! ```toml
//! urdf = "cdhrm5.urdf"           # path relative to this file
//! tip_link = "end_effector"      # its origin is the end-effector point
//! gravity = [0.0, 9.81, 0.0]     # m/s², base frame (the mounting)
//! payload = 0.8                  # kg, optional: the stated load capability (Table I)
//! ```

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde::Deserialize;

use crate::error::{Result, RobotError};
use crate::model::{ChainSettings, Robot};

/// The name of the description file inside a robot folder.
pub const DESCRIPTION_FILE: &str = "robot.toml";

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DescriptionFile {
    urdf: PathBuf,
    tip_link: String,
    gravity: [f64; 3],
    #[serde(default)]
    payload: Option<f64>,
}

/// A robot folder's description, read from its `robot.toml`.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotDescription {
    /// The folder holding `robot.toml` (relative paths in it are resolved against it).
    pub dir: PathBuf,
    /// The description file itself.
    pub path: PathBuf,
    /// The URDF file.
    pub urdf: PathBuf,
    /// Tip link and gravity.
    pub settings: ChainSettings,
    /// The platform's stated load capability, kg (informational: Table I).
    pub payload: Option<f64>,
}

impl RobotDescription {
    /// Read a description from a robot folder or from a `robot.toml` path.
    ///
    /// # Errors
    /// [`RobotError::Io`] when the file cannot be read, [`RobotError::InvalidDescription`]
    /// when it is not valid, [`RobotError::InvalidGravity`] for a non-finite gravity vector.
    pub fn read(path: impl AsRef<Path>) -> Result<RobotDescription> {
        let path = path.as_ref();
        let path = if path.is_dir() { path.join(DESCRIPTION_FILE) } else { path.to_path_buf() };
        let text = std::fs::read_to_string(&path)
            .map_err(|source| RobotError::Io { path: path.clone(), source })?;
        RobotDescription::from_toml_str(&text, path)
    }

    /// A description from the text of a `robot.toml`; `path` names the file in messages and
    /// its folder resolves the URDF's relative path (nothing is read: a caller that holds the
    /// URDF's text too builds the robot with [`Robot::from_urdf_str`] and [`Self::settings`],
    /// e.g. a model unpickled where the robot folder does not exist).
    ///
    /// # Errors
    /// [`RobotError::InvalidDescription`] when the text is not valid,
    /// [`RobotError::InvalidGravity`] for a non-finite gravity vector.
    pub fn from_toml_str(text: &str, path: impl AsRef<Path>) -> Result<RobotDescription> {
        let path = path.as_ref().to_path_buf();
        let file: DescriptionFile = toml::from_str(text).map_err(|e| {
            RobotError::InvalidDescription { path: path.clone(), message: e.to_string() }
        })?;
        if !file.gravity.iter().all(|g| g.is_finite()) {
            return Err(RobotError::InvalidGravity { path, gravity: file.gravity });
        }
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(RobotDescription {
            urdf: dir.join(&file.urdf),
            dir,
            path,
            payload: file.payload,
            settings: ChainSettings {
                tip_link: file.tip_link,
                gravity: Vector3::from(file.gravity),
            },
        })
    }

    /// Read the URDF and build the robot.
    ///
    /// # Errors
    /// [`RobotError::Io`] for a missing URDF, and every loader error of [`Robot::from_urdf_str`].
    pub fn load_robot(&self) -> Result<Robot> {
        let text = std::fs::read_to_string(&self.urdf)
            .map_err(|source| RobotError::Io { path: self.urdf.clone(), source })?;
        Robot::from_urdf_str(&text, &self.urdf.display().to_string(), &self.settings)
    }
}

/// Load a robot from a folder holding `robot.toml` (or from the `robot.toml` path itself).
///
/// # Errors
/// See [`RobotDescription::read`] and [`RobotDescription::load_robot`].
pub fn load(path: impl AsRef<Path>) -> Result<Robot> {
    RobotDescription::read(path)?.load_robot()
}

/// Load a robot straight from a URDF file with the given settings.
///
/// # Errors
/// [`RobotError::Io`] when the file cannot be read, and every loader error of
/// [`Robot::from_urdf_str`].
pub fn load_urdf(path: impl AsRef<Path>, settings: &ChainSettings) -> Result<Robot> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path)
        .map_err(|source| RobotError::Io { path: path.to_path_buf(), source })?;
    Robot::from_urdf_str(&text, &path.display().to_string(), settings)
}
