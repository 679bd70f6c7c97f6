//! The one error type of this crate.

use std::fmt;
use std::path::PathBuf;

use sinew_robot::{Compact, ErrorKind};

/// Where in a file an element starts: the file as named by the caller, 1-based line and column.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Place {
    /// The file (its path, or a name given with the text).
    pub file: String,
    /// Line, from 1.
    pub line: u32,
    /// Column, from 1 (in characters).
    pub column: u32,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

/// Everything that can go wrong while importing a model.
///
/// Every variant about a file carries the [`Place`] of the element at fault and names it
/// (`<link_rigid num="2" name="M2">`, cable `M1_1`, …), so that a message read on its own says
/// what to fix and where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    /// A file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// The text is not well-formed XML.
    #[error("{at}: not well-formed XML: {message}")]
    Xml {
        /// Where the parser stopped.
        at: Place,
        /// What the XML parser said.
        message: String,
    },
    /// The document's root element is not the one this file should have.
    #[error("{at}: root element is <{found}>, expected <{expected}>")]
    UnexpectedRoot {
        /// The root element.
        at: Place,
        /// The element CASPR requires.
        expected: &'static str,
        /// The element found.
        found: String,
    },
    /// A required child element is missing.
    #[error("{at}: {parent} has no <{element}>")]
    MissingElement {
        /// The parent element.
        at: Place,
        /// The parent element, named.
        parent: String,
        /// The missing child.
        element: &'static str,
    },
    /// A required attribute is missing or empty.
    #[error("{at}: {element} has no `{attribute}` attribute")]
    MissingAttribute {
        /// The element.
        at: Place,
        /// The element, named.
        element: String,
        /// The missing attribute.
        attribute: &'static str,
    },
    /// An element this importer does not know where it expects CASPR's.
    #[error("{at}: unexpected {element} in {parent}: expected {expected}")]
    UnexpectedElement {
        /// The element.
        at: Place,
        /// The element, named.
        element: String,
        /// Its parent, named.
        parent: String,
        /// What may stand there.
        expected: &'static str,
    },
    /// A number (or list of numbers) that does not read as finite numbers of the right count.
    #[error("{at}: {element}: {field} = `{text}` is not {expected}")]
    InvalidNumber {
        /// The element holding it.
        at: Place,
        /// The element, named.
        element: String,
        /// The child element (`<mass>`) or attribute (`q_min`).
        field: String,
        /// The text found.
        text: String,
        /// What it should be.
        expected: &'static str,
    },
    /// An attribute with a value outside its set (`ref`, `attachment_reference`).
    #[error("{at}: {element}: {attribute} = \"{value}\": expected {expected}")]
    InvalidAttribute {
        /// The element.
        at: Place,
        /// The element, named.
        element: String,
        /// The attribute.
        attribute: &'static str,
        /// Its value.
        value: String,
        /// The values allowed.
        expected: &'static str,
    },
    /// The `<links>` element holds no link.
    #[error("{at}: <links> holds no <link_rigid>")]
    NoLinks {
        /// The `<links>` element.
        at: Place,
    },
    /// A link's `num` is not its position (CASPR numbers links 1, 2, … in file order).
    #[error("{at}: {element}: num should be {expected} (links are numbered 1, 2, … in file order)")]
    LinkOrder {
        /// The link.
        at: Place,
        /// The link, named.
        element: String,
        /// Its position in the file, from 1.
        expected: usize,
    },
    /// A joint type Sinew cannot represent (spherical, prismatic, planar, spatial, an axis
    /// joint, or a type CASPR does not know either).
    #[error(
        "{at}: link {link} `{name}`: joint type `{joint_type}` is not supported: Sinew imports R_X, R_Y, R_Z (one revolute joint) and U_XY, U_XZ, U_YZ (universal joints)"
    )]
    UnsupportedJoint {
        /// The `<joint>` element.
        at: Place,
        /// The link's `num`.
        link: usize,
        /// The link's `name`.
        name: String,
        /// The joint type as written.
        joint_type: String,
    },
    /// A link's parent number names no link.
    #[error(
        "{at}: link {link} `{name}`: parent {parent} does not exist (links 0 = base, 1 to {links})"
    )]
    MissingParent {
        /// The `<parent>` element.
        at: Place,
        /// The link's `num`.
        link: usize,
        /// The link's `name`.
        name: String,
        /// The parent number given.
        parent: usize,
        /// How many links the file defines.
        links: usize,
    },
    /// A link whose parent is not the link before it: a tree, which Sinew's serial chain cannot
    /// hold.
    #[error(
        "{at}: link {link} `{name}`: parent {parent} is not the previous link {expected}: Sinew imports serial chains only"
    )]
    NotSerial {
        /// The `<parent>` element.
        at: Place,
        /// The link's `num`.
        link: usize,
        /// The link's `name`.
        name: String,
        /// The parent number given.
        parent: usize,
        /// The parent a serial chain needs (`link − 1`).
        expected: usize,
    },
    /// Joint limits with `q_min > q_max`.
    #[error("{at}: link {link} `{name}`: joint limits q_min > q_max for coordinate {coordinate}: [{}, {}] rad", Compact(*.lower), Compact(*.upper))]
    InvalidJointLimits {
        /// The `<joint>` element.
        at: Place,
        /// The link's `num`.
        link: usize,
        /// The link's `name`.
        name: String,
        /// The joint coordinate, from 1.
        coordinate: usize,
        /// q_min.
        lower: f64,
        /// q_max.
        upper: f64,
    },
    /// No `<cable_set>` has the id asked for (or the `default_cable_set`).
    #[error("{at}: no <cable_set id=\"{id}\">: the file has {}", list(.known))]
    UnknownCableSet {
        /// The `<cables>` root element.
        at: Place,
        /// The id asked for.
        id: String,
        /// The ids the file has.
        known: Vec<String>,
    },
    /// No `<operational_set>` has the file's `default_operational_set` id.
    #[error("{at}: no <operational_set id=\"{id}\">: the file has {}", list(.known))]
    UnknownOperationalSet {
        /// The `<operational_spaces>` root element.
        at: Place,
        /// The id asked for.
        id: String,
        /// The ids the file has.
        known: Vec<String>,
    },
    /// The operational set has no space with a point (`<link>` and `<offset>`).
    #[error(
        "{at}: operational set `{id}` has no space with a <link> and an <offset> (position or pose_euler_xyz) to make the tip point"
    )]
    NoOperationalPoint {
        /// The `<operational_set>` element.
        at: Place,
        /// Its id.
        id: String,
    },
    /// The operational point sits on a link that is not the last one: a fixed tip link there
    /// would branch the chain.
    #[error(
        "{at}: the operational point is on link {link}, not on the last link {last}: Sinew's tip must end the chain"
    )]
    TipNotOnLastLink {
        /// The `<link>` element of the operational space.
        at: Place,
        /// The link given.
        link: usize,
        /// The last link.
        last: usize,
    },
    /// A cable model Sinew cannot take (pulleys, VSD springs, muscles).
    #[error(
        "{at}: cable `{cable}`: <{kind}> is not supported: Sinew imports <cable_ideal> and <cable_linear_spring>"
    )]
    UnsupportedCable {
        /// The cable element.
        at: Place,
        /// The cable's name.
        cable: String,
        /// The element name.
        kind: String,
    },
    /// An attachment other than a point (`base_rotating_pulley`, …).
    #[error("{at}: cable `{cable}`: <{kind}> is not supported: Sinew imports point <attachment>s")]
    UnsupportedAttachment {
        /// The attachment element.
        at: Place,
        /// The cable's name.
        cable: String,
        /// The element name.
        kind: String,
    },
    /// An attachment on a link the bodies file does not define.
    #[error(
        "{at}: cable `{cable}`: attachment on link {link}, but the bodies file has links 0 (base) to {links}"
    )]
    UnknownAttachmentLink {
        /// The `<link>` element of the attachment.
        at: Place,
        /// The cable's name.
        cable: String,
        /// The link given.
        link: usize,
        /// How many links the bodies file defines.
        links: usize,
    },
    /// A cable with fewer than two attachments.
    #[error("{at}: cable `{cable}` has {count} attachment(s): at least 2 are needed")]
    TooFewAttachments {
        /// The cable element.
        at: Place,
        /// The cable's name.
        cable: String,
        /// The attachments found.
        count: usize,
    },
    /// Two cables of the set share a name.
    #[error("{at}: cable `{cable}` is defined twice in the set")]
    DuplicateCable {
        /// The second cable element.
        at: Place,
        /// The name.
        cable: String,
    },
    /// The chosen cable set holds no cable.
    #[error("{at}: cable set `{id}` holds no cable")]
    EmptyCableSet {
        /// The `<cable_set>` element.
        at: Place,
        /// Its id.
        id: String,
    },
    /// A cable's `force_min`/`force_max` that no clamping can make valid (`f_min ≥ f_max`).
    #[error(
        "{at}: cable `{cable}`: force limits [{}, {}] N: need force_min < force_max", Compact(*.f_min), Compact(*.f_max)
    )]
    InvalidTensionLimits {
        /// The `<properties>` element.
        at: Place,
        /// The cable's name.
        cable: String,
        /// force_min.
        f_min: f64,
        /// force_max.
        f_max: f64,
    },
    /// An import option out of its range.
    #[error("{option} = {}: expected {expected}", Compact(*.value))]
    InvalidOption {
        /// The option (`youngs_modulus`, `tension_limits`, …).
        option: &'static str,
        /// The value given.
        value: f64,
        /// What it should be.
        expected: &'static str,
    },
}

fn list(ids: &[String]) -> String {
    if ids.is_empty() {
        "none".to_owned()
    } else {
        ids.iter().map(|id| format!("`{id}`")).collect::<Vec<_>>().join(", ")
    }
}

impl ImportError {
    /// The kind of failure: every import error is about the files or the options given
    /// ([`ErrorKind::Input`]).
    pub fn kind(&self) -> ErrorKind {
        use ImportError::*;
        // No wildcard: a new variant must be classified here.
        match self {
            Io { .. }
            | Xml { .. }
            | UnexpectedRoot { .. }
            | MissingElement { .. }
            | MissingAttribute { .. }
            | UnexpectedElement { .. }
            | InvalidNumber { .. }
            | InvalidAttribute { .. }
            | NoLinks { .. }
            | LinkOrder { .. }
            | UnsupportedJoint { .. }
            | MissingParent { .. }
            | NotSerial { .. }
            | InvalidJointLimits { .. }
            | UnknownCableSet { .. }
            | UnknownOperationalSet { .. }
            | NoOperationalPoint { .. }
            | TipNotOnLastLink { .. }
            | UnsupportedCable { .. }
            | UnsupportedAttachment { .. }
            | UnknownAttachmentLink { .. }
            | TooFewAttachments { .. }
            | DuplicateCable { .. }
            | EmptyCableSet { .. }
            | InvalidTensionLimits { .. }
            | InvalidOption { .. } => ErrorKind::Input,
        }
    }

    /// Where in which file the error is, when it is about a file's element.
    pub fn place(&self) -> Option<&Place> {
        use ImportError::*;
        match self {
            Io { .. } | InvalidOption { .. } => None,
            Xml { at, .. }
            | UnexpectedRoot { at, .. }
            | MissingElement { at, .. }
            | MissingAttribute { at, .. }
            | UnexpectedElement { at, .. }
            | InvalidNumber { at, .. }
            | InvalidAttribute { at, .. }
            | NoLinks { at }
            | LinkOrder { at, .. }
            | UnsupportedJoint { at, .. }
            | MissingParent { at, .. }
            | NotSerial { at, .. }
            | InvalidJointLimits { at, .. }
            | UnknownCableSet { at, .. }
            | UnknownOperationalSet { at, .. }
            | NoOperationalPoint { at, .. }
            | TipNotOnLastLink { at, .. }
            | UnsupportedCable { at, .. }
            | UnsupportedAttachment { at, .. }
            | UnknownAttachmentLink { at, .. }
            | TooFewAttachments { at, .. }
            | DuplicateCable { at, .. }
            | EmptyCableSet { at, .. }
            | InvalidTensionLimits { at, .. } => Some(at),
        }
    }
}

/// The result of this crate's functions.
pub type Result<T, E = ImportError> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_import_error_is_input() {
        let at = || Place { file: "bodies.xml".into(), line: 3, column: 5 };
        let cases = [
            ImportError::Io {
                path: "bodies.xml".into(),
                source: std::io::ErrorKind::NotFound.into(),
            },
            ImportError::Xml { at: at(), message: "unexpected end".into() },
            ImportError::NoLinks { at: at() },
            ImportError::EmptyCableSet { at: at(), id: "default".into() },
            ImportError::InvalidOption { option: "youngs_modulus", value: -1.0, expected: "> 0" },
        ];
        for e in cases {
            assert_eq!(e.kind(), ErrorKind::Input, "{e}");
        }
    }
}
