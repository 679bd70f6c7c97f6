//! The cables file (`<cables default_cable_set=…><cable_set id=…>`): CASPR's
//! `ModelConfigBase` (the default set), `SystemModelCables.LoadXmlObj`,
//! `CableModelIdeal.LoadXmlObj` / `CableModelLinearSpring.LoadXmlObj`,
//! `CableModelBase.LoadSegmentsXmlObj` and `CableAttachmentPoint`.

use std::collections::HashSet;

use roxmltree::Node;

use crate::bodies::Link;
use crate::error::{ImportError, Place, Result};
use crate::xml::{Xml, describe, elements, optional_child};

/// One attachment of a cable: a point fixed in a link's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Attachment {
    /// The link (0 = base).
    pub link: usize,
    /// The point in the link's frame (the joint frame), m, whatever reference the file used.
    pub point: [f64; 3],
}

/// One cable of the chosen set.
#[derive(Debug, Clone, PartialEq)]
pub struct Cable {
    /// CASPR's `name`.
    pub name: String,
    /// `force_min`, N, as written.
    pub force_min: f64,
    /// `force_max`, N, as written.
    pub force_max: f64,
    /// The attachments from the first to the last, as written (CASPR's segments join
    /// consecutive ones).
    pub attachments: Vec<Attachment>,
    /// The cable's element, and its `<properties>` (for messages about its limits).
    pub(crate) place: Place,
    pub(crate) properties: Place,
    /// The XML element name (`cable_ideal`, `cable_linear_spring`).
    pub kind: String,
}

/// The chosen cable set.
#[derive(Debug, Clone, PartialEq)]
pub struct CableSet {
    /// Its id.
    pub id: String,
    /// Whether it is the file's `default_cable_set` (no id was asked for).
    pub is_default: bool,
    /// Its cables in file order.
    pub cables: Vec<Cable>,
}

/// Read the set `id` (or the file's `default_cable_set`) of a cables file against `links`.
pub(crate) fn read_cable_set(xml: &Xml<'_>, links: &[Link], id: Option<&str>) -> Result<CableSet> {
    let root = xml.root("cables")?;
    let (id, is_default) = match id {
        Some(id) => (id.to_owned(), false),
        None => (xml.attribute(root, "default_cable_set")?.to_owned(), true),
    };
    let sets: Vec<Node<'_, '_>> =
        elements(root).filter(|n| n.tag_name().name() == "cable_set").collect();
    let set = sets.iter().find(|s| s.attribute("id") == Some(id.as_str())).ok_or_else(|| {
        ImportError::UnknownCableSet {
            at: xml.place(root),
            id: id.clone(),
            known: sets.iter().filter_map(|s| s.attribute("id")).map(str::to_owned).collect(),
        }
    })?;
    let mut cables = Vec::new();
    let mut names = HashSet::new();
    for node in elements(*set) {
        let cable = read_cable(xml, node, links)?;
        if !names.insert(cable.name.clone()) {
            return Err(ImportError::DuplicateCable { at: cable.place, cable: cable.name });
        }
        cables.push(cable);
    }
    if cables.is_empty() {
        return Err(ImportError::EmptyCableSet { at: xml.place(*set), id });
    }
    Ok(CableSet { id, is_default, cables })
}

fn read_cable(xml: &Xml<'_>, node: Node<'_, '_>, links: &[Link]) -> Result<Cable> {
    let kind = node.tag_name().name().to_owned();
    let name = xml.attribute(node, "name")?.to_owned();
    if kind != "cable_ideal" && kind != "cable_linear_spring" {
        return Err(ImportError::UnsupportedCable { at: xml.place(node), cable: name, kind });
    }
    let reference = xml.attribute(node, "attachment_reference")?;
    let com_reference = match reference {
        "joint" => false,
        "com" => true,
        other => {
            return Err(ImportError::InvalidAttribute {
                at: xml.place(node),
                element: describe(node),
                attribute: "attachment_reference",
                value: other.to_owned(),
                expected: "\"joint\" or \"com\"",
            });
        }
    };
    let properties = xml.child(node, "properties")?;
    let force_min = xml.child_number(properties, "force_min")?;
    let force_max = xml.child_number(properties, "force_max")?;

    let attachments_node = xml.child(node, "attachments")?;
    let mut attachments = Vec::new();
    for a in elements(attachments_node) {
        if a.tag_name().name() != "attachment" {
            return Err(ImportError::UnsupportedAttachment {
                at: xml.place(a),
                cable: name,
                kind: a.tag_name().name().to_owned(),
            });
        }
        let (link, link_node) = xml.child_index(a, "link")?;
        if link > links.len() {
            return Err(ImportError::UnknownAttachmentLink {
                at: xml.place(link_node),
                cable: name,
                link,
                links: links.len(),
            });
        }
        let location = xml.child_vector(a, "location")?;
        // CableAttachmentPoint: r_GA = r_A (com) or r_A − r_PG (joint); the point in the link
        // frame is r_PG + r_GA, r_PG = 0 on the base.
        let point = if com_reference && link > 0 {
            let g = links[link - 1].com;
            [g[0] + location[0], g[1] + location[1], g[2] + location[2]]
        } else {
            location
        };
        attachments.push(Attachment { link, point });
    }
    if attachments.len() < 2 {
        return Err(ImportError::TooFewAttachments {
            at: xml.place(attachments_node),
            cable: name,
            count: attachments.len(),
        });
    }
    // Unused but checked, so that a typo is not silently ignored.
    if let Some(d) = optional_child(properties, "diameter") {
        xml.numbers(d, "<diameter>", crate::xml::text(d), Some(1), "a finite number")?;
    }
    Ok(Cable {
        name,
        force_min,
        force_max,
        attachments,
        place: xml.place(node),
        properties: xml.place(properties),
        kind,
    })
}
