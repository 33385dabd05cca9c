//! The shared options and crosslinking of the filament generators
//! (`filament`, `network`, `aster`, `cortex`, …): the chain options, the
//! crosslinker types and the crosslinks between filaments where they cross.

use glam::DVec3;

use std::fmt::Write as _;

use super::{min_mean_max, positive, Draws, Writer};
use crate::units::BOLTZMANN_PN_UM_PER_K;

/// The filament options every chain generator shares.
#[derive(clap::Args, Clone, Debug)]
pub struct Chain {
    /// Contour length of each filament (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub length: f64,
    /// Bonds per filament (n + 1 beads); or give --segment-length.
    #[arg(long, conflicts_with = "segment_length")]
    pub segments: Option<u32>,
    /// Target segment length ℓ (µm): n = round(L/ℓ) segments of exactly L/n.
    #[arg(allow_negative_numbers = true, long)]
    pub segment_length: Option<f64>,
    /// Particle type of the beads.
    #[arg(long, default_value = "bead")]
    pub particle_type: String,
    /// Bond type between consecutive beads.
    #[arg(long, default_value = "segment")]
    pub bond_type: String,
    /// Angle type on consecutive bead triples (bending).
    #[arg(long, default_value = "bend")]
    pub angle_type: String,
    /// Persistence length Lp (µm) for the printed bending stiffness
    /// [default: 17 (actin); 5200 for `aster` (microtubules)].
    #[arg(allow_negative_numbers = true, long)]
    pub persistence_length: Option<f64>,
    /// Temperature (K) of kT in κ = Lp·kT.
    #[arg(allow_negative_numbers = true, long, default_value_t = 298.0)]
    pub temperature: f64,
}

impl Default for Chain {
    fn default() -> Self {
        Self {
            length: 1.0,
            segments: Some(10),
            segment_length: None,
            particle_type: "bead".into(),
            bond_type: "segment".into(),
            angle_type: "bend".into(),
            persistence_length: None,
            temperature: 298.0,
        }
    }
}

impl Chain {
    /// The segment count n and length ℓ = L/n, checked.
    pub fn segmentation(&self) -> Result<(usize, f64), String> {
        positive("--length", self.length)?;
        let n = match (self.segments, self.segment_length) {
            (Some(0), _) => return Err("expected --segments >= 1, found 0".into()),
            (Some(n), _) => n as usize,
            (None, Some(l)) => (self.length / positive("--segment-length", l)?).round().max(1.0) as usize,
            (None, None) => return Err("expected --segments N or --segment-length L".into()),
        };
        if n > 10_000_000 {
            return Err(format!("expected at most 10 000 000 segments per filament, found {n}"));
        }
        Ok((n, self.length / n as f64))
    }

    /// κ = Lp·kT (pN·µm²) and the summary line with the force-field lines,
    /// for segments of length `ell` (the bond rest length).
    pub fn bending_line(&self, ell: f64, default_lp: f64) -> Result<(f64, String), String> {
        let lp = positive("--persistence-length", self.persistence_length.unwrap_or(default_lp))?;
        let t = positive("--temperature", self.temperature)?;
        let kt = BOLTZMANN_PN_UM_PER_K * t;
        let kappa = lp * kt;
        let k = kappa / ell;
        Ok((
            kappa,
            format!(
                "bending: κ = Lp·kT = {kappa:.6e} pN·µm² (Lp {lp} µm, kT {kt:.6e} pN·µm at {t} K); per angle K = κ/ℓ = {k:.6e} pN·µm: `angle {a} wlc_bending kappa {kappa:.6e} l0 {ell:.6e}` or `angle {a} cosine_angle K {k:.6e}`",
                a = self.angle_type
            ),
        ))
    }

    /// Writes one chain through `points`: beads, bonds between neighbours and
    /// angles on every consecutive triple. Returns the bead ids.
    pub(crate) fn write(&self, w: &mut Writer, points: &[DVec3]) -> Vec<u64> {
        self.write_with_ends(w, points, [&self.particle_type, &self.particle_type])
    }

    /// [`write`](Self::write) with the first and last beads of particle types
    /// `ends` (anchored ends); the others are `--particle-type`.
    pub(crate) fn write_with_ends(&self, w: &mut Writer, points: &[DVec3], ends: [&str; 2]) -> Vec<u64> {
        let last = points.len() - 1;
        let type_of = |k: usize| match k {
            0 => ends[0],
            k if k == last => ends[1],
            _ => &self.particle_type,
        };
        let ids: Vec<u64> = points.iter().enumerate().map(|(k, p)| w.particle(type_of(k), *p, None)).collect();
        for pair in ids.windows(2) {
            w.bond(&self.bond_type, pair[0], pair[1]);
        }
        for triple in ids.windows(3) {
            w.angle(&self.angle_type, triple[0], triple[1], triple[2]);
        }
        ids
    }
}

/// Crosslinker bond types with the fraction of crosslinks each takes:
/// `xl_stiff:0.5,xl_soft:0.5` (a bare name takes fraction 1). Fractions are
/// normalised by their sum.
#[derive(Clone, Debug, PartialEq)]
pub struct CrosslinkerTypes(pub Vec<(String, f64)>);

impl Default for CrosslinkerTypes {
    fn default() -> Self {
        Self(vec![("crosslink".into(), 1.0)])
    }
}

impl std::str::FromStr for CrosslinkerTypes {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let mut types = Vec::new();
        for item in s.split(',') {
            let (name, fraction) = match item.split_once(':') {
                Some((name, f)) => (name.trim(), f.trim().parse::<f64>().map_err(|_| format!("found fraction `{f}`, expected a number"))?),
                None => (item.trim(), 1.0),
            };
            if name.is_empty() || name.contains(char::is_whitespace) || name.starts_with('#') {
                return Err(format!("found type name `{name}`, expected NAME:FRACTION[,NAME:FRACTION…]"));
            }
            if !(fraction.is_finite() && fraction >= 0.0) {
                return Err(format!("found fraction {fraction} for `{name}`, expected a fraction >= 0"));
            }
            if types.iter().any(|(n, _): &(String, f64)| n == name) {
                return Err(format!("crosslinker type `{name}` given twice"));
            }
            types.push((name.to_string(), fraction));
        }
        let sum: f64 = types.iter().map(|t| t.1).sum();
        if sum <= 0.0 {
            return Err("expected fractions summing to more than 0".into());
        }
        Ok(Self(types.into_iter().map(|(n, f)| (n, f / sum)).collect()))
    }
}

impl CrosslinkerTypes {
    /// The type for a uniform draw `u` in (0, 1): by cumulative fraction.
    pub fn pick(&self, u: f64) -> usize {
        let mut acc = 0.0;
        for (k, (_, f)) in self.0.iter().enumerate() {
            acc += f;
            if u < acc {
                return k;
            }
        }
        self.0.iter().rposition(|t| t.1 > 0.0).unwrap_or(0)
    }
}

/// Crosslinks written by [`crosslink`]: (type index, bead ids, length).
pub(crate) struct Crosslinks {
    pub links: Vec<(usize, u64, u64, f64)>,
}

impl Crosslinks {
    /// Writes the crosslinks as bonds, picking each one's type from its draw.
    pub fn from_pairs(pairs: Vec<(u64, u64, f64)>, types: &CrosslinkerTypes, draws: &Draws, purpose: u32) -> Self {
        let links = pairs.into_iter().enumerate().map(|(k, (i, j, d))| (types.pick(draws.uniform(k as u64, purpose)), i, j, d)).collect();
        Self { links }
    }

    pub fn write(&self, w: &mut Writer, types: &CrosslinkerTypes) {
        for &(t, i, j, _) in &self.links {
            w.bond(&types.0[t].0, i, j);
        }
    }

    /// For each crosslink between bead i and its partner j, the bond of the
    /// same type from i to whichever neighbour of j along j's filament is
    /// nearer to i (separations through `minimum_image`).
    pub fn pins(&self, filaments: &[(Vec<u64>, Vec<DVec3>)], minimum_image: impl Fn(DVec3) -> DVec3) -> Self {
        let mut place = std::collections::HashMap::new();
        for (f, (ids, _)) in filaments.iter().enumerate() {
            place.extend(ids.iter().enumerate().map(|(k, id)| (*id, (f, k))));
        }
        let position = |id: u64| {
            let (f, k) = place[&id];
            filaments[f].1[k]
        };
        let links = self
            .links
            .iter()
            .filter_map(|&(t, i, j, _)| {
                let (f, k) = place[&j];
                let ids = &filaments[f].0;
                let neighbours = [k.checked_sub(1), (k + 1 < ids.len()).then_some(k + 1)];
                let distance = |n: usize| minimum_image(filaments[f].1[n] - position(i)).length();
                let nearer = neighbours.into_iter().flatten().min_by(|&a, &b| distance(a).total_cmp(&distance(b)))?;
                Some((t, i, ids[nearer], distance(nearer)))
            })
            .collect();
        Self { links }
    }

    /// `M crosslinks (a 12, b 9); length min … mean … max …`.
    pub fn summary(&self, types: &CrosslinkerTypes) -> String {
        let counts: Vec<String> =
            types.0.iter().enumerate().map(|(t, (name, _))| format!("{name} {}", self.links.iter().filter(|l| l.0 == t).count())).collect();
        let mut s = format!("{} crosslinks ({})", self.links.len(), counts.join(", "));
        if !self.links.is_empty() {
            let [lo, mean, hi] = min_mean_max(&self.links.iter().map(|l| l.3).collect::<Vec<_>>());
            write!(s, "; crosslink length min {lo:.6e} mean {mean:.6e} max {hi:.6e} (for r0)").unwrap();
        }
        s
    }
}

/// For every pair of filaments (bead ids and positions), the closest pair of
/// their beads if it is closer than `capture` (separations through
/// `minimum_image`): one crosslink per pair of filaments, where they cross.
pub(crate) fn closest_pairs(
    filaments: &[(Vec<u64>, Vec<DVec3>)],
    capture: f64,
    minimum_image: impl Fn(DVec3) -> DVec3,
) -> Vec<(u64, u64, f64)> {
    // Bounding spheres: skip pairs whose centres are too far apart.
    let spheres: Vec<(DVec3, f64)> = filaments
        .iter()
        .map(|(_, x)| {
            let c = x.iter().copied().sum::<DVec3>() / x.len() as f64;
            (c, x.iter().map(|p| (*p - c).length()).fold(0.0, f64::max))
        })
        .collect();
    let mut out = Vec::new();
    for a in 0..filaments.len() {
        for b in a + 1..filaments.len() {
            if minimum_image(spheres[b].0 - spheres[a].0).length() > spheres[a].1 + spheres[b].1 + capture {
                continue;
            }
            let mut best: Option<(u64, u64, f64)> = None;
            for (i, xi) in filaments[a].0.iter().zip(&filaments[a].1) {
                for (j, xj) in filaments[b].0.iter().zip(&filaments[b].1) {
                    let d = minimum_image(*xj - *xi).length();
                    if d < capture && best.is_none_or(|(_, _, bd)| d < bd) {
                        best = Some((*i, *j, d));
                    }
                }
            }
            out.extend(best);
        }
    }
    out
}
