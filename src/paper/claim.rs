//! A claim of the paper and its verdict: what every experiment's checks return ([`Claim`]).

/// A claim of the paper, whether it holds in our model, and the numbers behind the verdict.
#[derive(Debug, Clone, PartialEq)]
pub struct Claim {
    /// Which experiment and what the paper says.
    pub claim: String,
    /// Whether our numbers show it.
    pub holds: bool,
    /// Whether the numbers needed exist (e.g. not when an equilibrium is unstable).
    pub checkable: bool,
    /// The numbers behind the verdict.
    pub evidence: String,
}

impl Claim {
    /// A claim checked against numbers.
    pub fn checked(claim: impl Into<String>, holds: bool, evidence: impl Into<String>) -> Claim {
        Claim { claim: claim.into(), holds, checkable: true, evidence: evidence.into() }
    }

    /// A claim that cannot be checked, and why.
    pub fn unchecked(claim: impl Into<String>, why: &str) -> Claim {
        Claim {
            claim: claim.into(),
            holds: false,
            checkable: false,
            evidence: format!("cannot be checked: {why}"),
        }
    }

    /// `holds`, `does not hold`, or `cannot be checked`.
    pub fn verdict(&self) -> &'static str {
        match (self.checkable, self.holds) {
            (false, _) => "cannot be checked",
            (true, true) => "holds",
            (true, false) => "does not hold",
        }
    }
}
