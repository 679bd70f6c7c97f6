//! The operational spaces file (`<operational_spaces default_operational_set=…>`): CASPR's
//! `ModelConfigBase` (the default set), `SystemModelBodies.load_operational_space_xml_obj` and
//! `OperationalPosition.LoadXmlObj` (a `<link>` and an `<offset>` from the link's joint, in its
//! frame: `r_OY = r_OP + r_y`).

use crate::error::{ImportError, Place, Result};
use crate::xml::{Xml, elements, optional_child};

/// The point an operational space names.
#[derive(Debug, Clone, PartialEq)]
pub struct OperationalPoint {
    /// The operational set's id.
    pub set: String,
    /// The space's name (its `name` attribute, else its element name).
    pub name: String,
    /// The link it sits on.
    pub link: usize,
    /// The point in that link's frame, m.
    pub offset: [f64; 3],
    /// The `<link>` element (for messages).
    pub(crate) place: Place,
    /// Spaces of the set after the first one with a point (ignored).
    pub ignored: usize,
}

/// The point of the file's default operational set, or `None` when the file names no default
/// set (`default_operational_set=""`, as CASPR's templates write).
pub(crate) fn read_operational_point(
    xml: &Xml<'_>,
    links: usize,
) -> Result<Option<OperationalPoint>> {
    let root = xml.root("operational_spaces")?;
    let id = match root.attribute("default_operational_set").map(str::trim) {
        Some(id) if !id.is_empty() => id,
        _ => return Ok(None),
    };
    let sets: Vec<_> =
        elements(root).filter(|n| n.tag_name().name() == "operational_set").collect();
    let set = sets.iter().find(|s| s.attribute("id") == Some(id)).ok_or_else(|| {
        ImportError::UnknownOperationalSet {
            at: xml.place(root),
            id: id.to_owned(),
            known: sets.iter().filter_map(|s| s.attribute("id")).map(str::to_owned).collect(),
        }
    })?;
    let spaces: Vec<_> = elements(*set)
        .filter(|s| optional_child(*s, "link").is_some() && optional_child(*s, "offset").is_some())
        .collect();
    let Some(space) = spaces.first() else {
        return Err(ImportError::NoOperationalPoint { at: xml.place(*set), id: id.to_owned() });
    };
    let (link, link_node) = xml.child_index(*space, "link")?;
    if link == 0 || link > links {
        return Err(ImportError::TipNotOnLastLink { at: xml.place(link_node), link, last: links });
    }
    let offset = xml.child_vector(*space, "offset")?;
    Ok(Some(OperationalPoint {
        set: id.to_owned(),
        name: space.attribute("name").unwrap_or(space.tag_name().name()).to_owned(),
        link,
        offset,
        place: xml.place(link_node),
        ignored: spaces.len() - 1,
    }))
}
