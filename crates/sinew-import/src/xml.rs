//! Reading CASPR's XML: one parsed document with its file name, and the lookups every file
//! needs (a child element, an attribute, numbers), each failing with the element's place.

use roxmltree::{Document, Node};

use crate::error::{ImportError, Place, Result};

/// A parsed XML file.
pub(crate) struct Xml<'input> {
    pub(crate) file: &'input str,
    pub(crate) doc: Document<'input>,
}

impl<'input> Xml<'input> {
    /// Parse `text`, naming it `file` in errors. DTDs are allowed (CASPR's files declare one).
    pub(crate) fn parse(file: &'input str, text: &'input str) -> Result<Xml<'input>> {
        let options = roxmltree::ParsingOptions { allow_dtd: true, ..Default::default() };
        let doc = Document::parse_with_options(text, options).map_err(|e| {
            let pos = e.pos();
            ImportError::Xml {
                at: Place { file: file.to_owned(), line: pos.row, column: pos.col },
                message: e.to_string(),
            }
        })?;
        Ok(Xml { file, doc })
    }

    /// The root element, checked to be `<expected>`.
    pub(crate) fn root(&self, expected: &'static str) -> Result<Node<'_, 'input>> {
        let root = self.doc.root_element();
        if root.tag_name().name() != expected {
            return Err(ImportError::UnexpectedRoot {
                at: self.place(root),
                expected,
                found: root.tag_name().name().to_owned(),
            });
        }
        Ok(root)
    }

    /// Where `node` starts.
    pub(crate) fn place(&self, node: Node<'_, '_>) -> Place {
        let pos = self.doc.text_pos_at(node.range().start);
        Place { file: self.file.to_owned(), line: pos.row, column: pos.col }
    }

    /// The first child element `<name>` of `node`.
    pub(crate) fn child<'a>(
        &self,
        node: Node<'a, 'input>,
        name: &'static str,
    ) -> Result<Node<'a, 'input>> {
        optional_child(node, name).ok_or_else(|| ImportError::MissingElement {
            at: self.place(node),
            parent: describe(node),
            element: name,
        })
    }

    /// A non-empty attribute.
    pub(crate) fn attribute<'a>(
        &self,
        node: Node<'a, 'input>,
        name: &'static str,
    ) -> Result<&'a str> {
        node.attribute(name).filter(|v| !v.trim().is_empty()).ok_or_else(|| {
            ImportError::MissingAttribute {
                at: self.place(node),
                element: describe(node),
                attribute: name,
            }
        })
    }

    /// Whitespace-separated finite numbers, `count` of them when `count` is given.
    pub(crate) fn numbers(
        &self,
        node: Node<'_, '_>,
        field: &str,
        text: &str,
        count: Option<usize>,
        expected: &'static str,
    ) -> Result<Vec<f64>> {
        let invalid = || ImportError::InvalidNumber {
            at: self.place(node),
            element: describe(node),
            field: field.to_owned(),
            text: text.trim().to_owned(),
            expected,
        };
        let values = text
            .split_whitespace()
            .map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<Vec<f64>>>()
            .ok_or_else(invalid)?;
        match count {
            Some(n) if values.len() != n => Err(invalid()),
            None if values.is_empty() => Err(invalid()),
            _ => Ok(values),
        }
    }

    /// The text of child `<name>` as one finite number.
    pub(crate) fn child_number(&self, node: Node<'_, 'input>, name: &'static str) -> Result<f64> {
        let child = self.child(node, name)?;
        let values =
            self.numbers(child, &format!("<{name}>"), text(child), Some(1), "a finite number")?;
        Ok(values[0])
    }

    /// The text of child `<name>` as three finite numbers.
    pub(crate) fn child_vector(
        &self,
        node: Node<'_, 'input>,
        name: &'static str,
    ) -> Result<[f64; 3]> {
        let child = self.child(node, name)?;
        let v = self.numbers(
            child,
            &format!("<{name}>"),
            text(child),
            Some(3),
            "three finite numbers",
        )?;
        Ok([v[0], v[1], v[2]])
    }

    /// The text of child `<name>` as a non-negative integer (a link number).
    pub(crate) fn child_index<'a>(
        &self,
        node: Node<'a, 'input>,
        name: &'static str,
    ) -> Result<(usize, Node<'a, 'input>)> {
        let child = self.child(node, name)?;
        let t = text(child).trim();
        t.parse::<usize>().map(|v| (v, child)).map_err(|_| ImportError::InvalidNumber {
            at: self.place(child),
            element: describe(child),
            field: format!("<{name}>"),
            text: t.to_owned(),
            expected: "a link number (0 = base, 1, 2, …)",
        })
    }
}

/// The first child element named `name`.
pub(crate) fn optional_child<'a, 'input>(
    node: Node<'a, 'input>,
    name: &str,
) -> Option<Node<'a, 'input>> {
    node.children().find(|c| c.is_element() && c.tag_name().name() == name)
}

/// The child elements of `node`.
pub(crate) fn elements<'a, 'input>(
    node: Node<'a, 'input>,
) -> impl Iterator<Item = Node<'a, 'input>> {
    node.children().filter(Node::is_element)
}

/// An element's text (empty when it has none).
pub(crate) fn text<'a>(node: Node<'a, '_>) -> &'a str {
    node.text().unwrap_or("")
}

/// An element named for messages: its tag and the attributes that identify it
/// (`<link_rigid num="2" name="M2">`, `<cable_ideal name="c1">`).
pub(crate) fn describe(node: Node<'_, '_>) -> String {
    let mut out = format!("<{}", node.tag_name().name());
    for key in ["num", "id", "name"] {
        if let Some(v) = node.attribute(key) {
            out.push_str(&format!(" {key}=\"{v}\""));
        }
    }
    out.push('>');
    out
}
