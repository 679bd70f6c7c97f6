//! The writers: the folder's three files as text, from what the import decided (`folder.rs`:
//! the names, the tip, the limits, the order of each cable's holes). They decide nothing and
//! warn about nothing; `urdf.rs` writes `<name>.urdf`, `toml_files.rs` writes `robot.toml` and
//! the explicit `cables.toml`, every TOML value through the `toml` crate.

pub(crate) mod toml_files;
pub(crate) mod urdf;

/// Where the tip sits, as decided: the link (by number, 0 the base), the point in its frame
/// and what it is (for the files' comments).
pub(crate) struct Tip {
    /// The CASPR link number the tip is fixed to.
    pub(crate) link: usize,
    /// The point in that link's frame, m.
    pub(crate) point: [f64; 3],
    /// What the point is, in words.
    pub(crate) what: String,
}

/// Text safe inside an XML comment (no `--`) or a TOML comment (one line, no control
/// character but the tab).
pub(crate) fn comment(s: &str) -> String {
    s.replace("--", "- -").replace(|c: char| c.is_control() && c != '\t', " ")
}

#[cfg(test)]
mod tests {
    use super::comment;

    #[test]
    fn comments_stay_one_line_without_double_dashes() {
        assert_eq!(comment("a--b"), "a- -b");
        assert_eq!(comment("a\nb\r\u{7f}c\td"), "a b  c\td");
    }
}
