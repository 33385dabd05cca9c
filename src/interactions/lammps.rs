//! What an interaction type's LAMMPS translation returns
//! ([`super::Interaction::lammps`], written in the interaction's own file):
//! the style or fix that computes the same energy and forces, with its
//! parameters converted, or `None` where LAMMPS has no equivalent. The
//! export (module `export`) writes these into the input script and owns
//! everything else (hybrid styles, groups, variables, probes).
//!
//! A translation sees the term's parameter values ([`LammpsTerm`]); an
//! external also sees the box and whether one of its parameters is an
//! expression ([`Moving`]), which only a wall's `d` of time can be in LAMMPS.

/// The term being translated.
pub struct LammpsTerm<'a> {
    /// Parameter values in schema order (after `coeff` changes).
    pub params: &'a [f64],
    /// The term's label in the force field or deck, for messages.
    pub label: &'a str,
    /// Box edge length along each axis (externals: walls are placed by it).
    pub box_lengths: [f64; 3],
    /// Whether each axis is periodic.
    pub periodic: [bool; 3],
    /// The expression parameters of an external.
    pub moving: Moving<'a>,
}

/// The expression parameters of an external term.
pub enum Moving<'a> {
    /// None: every parameter is a number.
    Fixed,
    /// One parameter, `index`, is a formula of time only: its LAMMPS formula
    /// (or why it has none), and the equal-style variable that may hold it.
    Time { index: usize, formula: Result<String, String>, variable: &'a str },
    /// Anything else (several, or reading x, y, z or `thermo`).
    Other,
}

/// How LAMMPS writes a term.
#[derive(Clone, Debug, PartialEq)]
pub enum LammpsStyle {
    /// A `bond_style` or `angle_style` sub-style and its coefficients.
    Bonded { style: &'static str, coeffs: String },
    /// A `pair_style` and its coefficients (cutoff included); `shift`: the
    /// energy is shifted to zero at the cutoff (`pair_modify shift yes`).
    Pair { style: &'static str, coeffs: String, shift: bool },
    /// A fix: its style and arguments after the group, and a `variable` line
    /// to write before it (a wall's face that moves with time).
    Fix { args: String, variable: Option<String> },
    /// `fix addforce` with one atom-style variable per parameter (force
    /// components, then energy), each a number or a formula of x, y, z, t.
    ParameterVariables,
    /// `fix addforce` with atom-style variables of −∇E and E of the term's
    /// energy expression (custom externals).
    ExpressionVariables,
}

/// A translation: `None` when LAMMPS cannot express the interaction at all,
/// an error when it cannot express these parameters.
pub type Translation = Option<Result<LammpsStyle, String>>;

/// A bonded sub-style.
pub fn bonded(style: &'static str, coeffs: String) -> Translation {
    Some(Ok(LammpsStyle::Bonded { style, coeffs }))
}

/// A pair style, not shifted.
pub fn pair(style: &'static str, coeffs: String) -> Translation {
    Some(Ok(LammpsStyle::Pair { style, coeffs, shift: false }))
}

/// A fix with no variable, for an external none of whose parameters is an
/// expression (`None` otherwise: the export then says which parameters LAMMPS
/// takes as expressions).
pub fn fix(term: &LammpsTerm, args: String) -> Translation {
    matches!(term.moving, Moving::Fixed).then_some(Ok(LammpsStyle::Fix { args, variable: None }))
}

/// Shortest text that reads back as exactly `x` (LAMMPS parses it with strtod).
pub fn num(x: f64) -> String {
    format!("{x:?}")
}

/// A `bond_style lepton` sub-style: `expression` of LAMMPS' lepton bond
/// variable r, which is the displacement r − r0.
pub fn lepton_bond(expression: String, r0: f64) -> Translation {
    bonded("lepton", format!("{} \"{expression}\"", num(r0)))
}
