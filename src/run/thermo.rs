//! Thermo output: aligned columns on stdout and a CSV file.
//!
//! Columns and their units (cell units shown; `cellmd` prints the active
//! system's units in the header):
//!
//! | column | meaning | unit |
//! |---|---|---|
//! | `step` | steps since the deck started | – |
//! | `time` | simulated time | s |
//! | `pe` | total potential energy, less the −F·x of `constant_force` externals (see `work`) | pN·µm |
//! | `work` | Σ F·x of the `constant_force` externals on their particles (unwrapped x); `pe − work` is the whole potential energy, LAMMPS' `pe` with `fix_modify … energy yes` | pN·µm |
//! | `pe/NAME` | potential energy of interaction type NAME, or of the active external NAME | pN·µm |
//! | `fx/NAME`, `fy/NAME`, `fz/NAME` | force of the active external NAME summed over its particles (a wall's or plate's load; the reaction is its negative) | pN |
//! | `fmax` | largest |F| on one particle | pN |
//! | `fnorm` | √(Σ|F|²) | pN |
//! | `press`, `pxx` … `pyz` | pressure tensor P = (N·kT/V)·I + W/V | Pa |
//! | `nbuild` | neighbour-list builds so far | – |
//! | `ctension/TYPE` | summed constraint tension of TYPE's constrained bonds (`constrain`) | pN |
//! | `solver_iterations`, `solver_residual` | CG iterations and relative residual of the last implicit step (0 for explicit steps) | – |
//! | `breaks`, `rebinds`, `forms`, `resets` | bond events so far | – |
//! | `nbound/TYPE` | bound bonds of bond type TYPE | – |
//! | `tension/TYPE` | summed tension of TYPE's bound bonds (clutch traction) | pN |
//! | `volume/BODYTYPE`, `area/BODYTYPE` | summed enclosed volume and area of the bodies of a type | µm³, µm² |
//! | `mindist` | smallest node–face distance between different bodies (exact below the largest contact d̂; `inf` when no pair is within the search range) | µm |
//! | `nclamp` | steps (explicit or implicit) and FIRE moves shortened by the contact step clamp so far | – |
//! | `planetension/AXIS/POS` | normal force transmitted across the plane x_AXIS = POS by every bond, pair, angle and body term crossing it; positive = tension ([`planes`]) | pN |
//! | `gamma/BODYTYPE` | cortical tension γ = ⟨Σ_cut T·\|û·n̂\|⟩/(2πR) over diametral planes of each body, mean over the type's bodies ([`planes`]) | pN/µm |
//! | `e2e/BONDTYPE` | mean end-to-end distance of the chains of bonds of the type ([`filaments`]) | µm |
//! | `tcorr/BONDTYPE/LAG` | tangent correlation ⟨t_s·t_{s+LAG}⟩ along those chains, LAG in bonds | – |
//! | `fracture/BONDTYPE/QUANTITY` | a sheet's junctions: `broken` original junctions, `rearranged` (bound junctions to new neighbours), `ratio` (rearranged per broken), largest `crack` (broken junctions), `pieces`, `label` (0 elastic, 1 ductile, 2 brittle) ([`fracture`]) | – |
//! | `clustering/BONDTYPE/GROUP_A/GROUP_B` | fibre clustering S_max/S_min: the densest 7 of 21 strips across the band between two cells against the 3 outermost at each end ([`clustering`]) | – |
//! | `fx/GROUP`, `fy/GROUP`, `fz/GROUP` | Σ_{i∈GROUP} F_i along the axis; on `fixed` particles the reaction of their anchors (a sheared plate's load) | pN |
//! | `xu/GROUP`, `yu/GROUP`, `zu/GROUP` | mean unwrapped coordinate (1/N)Σ_{i∈GROUP} (x_i + n_i·L) along the axis | µm |
//! | `load/NAME`, `depth/NAME` | an indenter external's load \|Σ F\| on its group (its reaction) and its deepest penetration δ = (3E/K)^{1/3} | pN, µm |

use std::fs::File;
use std::io::Write;
use std::path::PathBuf;

use super::protocol::indenter_load;
use crate::backend::Forces;
use crate::deck::{GroupQuantity, ThermoColumn};
use crate::interactions::REGISTRY;
use crate::measure::{clustering, filaments, fracture, planes};
use crate::output::records::RecordFile;
use crate::units::{Dim, UnitSystem};
use glam::DVec2;

/// What a thermo row reads: the system and the CPU backend after a force
/// evaluation at its state, with the run's counters and last solve. Values
/// that follow from these (the bond state, the box's volume and images,
/// the backend's tensions and neighbour-list builds) are read from them.
pub struct ThermoInputs<'a> {
    pub model: &'a crate::system::Model,
    pub state: &'a crate::system::State,
    pub sim_box: &'a crate::system::SimBox,
    /// The backend after a force evaluation at `state` (for measurements
    /// that read the force terms).
    pub backend: &'a crate::backend::CpuBackend,
    pub forces: &'a Forces,
    /// The context of the next step: its index and start time are the
    /// current state's, with the kT in force.
    pub context: crate::integrate::context::StepContext,
    pub kinetics: &'a crate::kinetics_engine::Kinetics,
    /// The last implicit step's linear solve.
    pub solve: crate::integrate::implicit::SolveReport,
    /// The constrained bonds and their last tensions.
    pub constraints: &'a crate::integrate::constraints::Constraints,
    /// Steps shortened by the contact step clamp so far.
    pub contact_clamps: u64,
}

/// A column's header name (bond-type columns name their type).
pub fn column_label(c: &ThermoColumn, model: &crate::system::Model) -> String {
    match c {
        ThermoColumn::Step => "step".into(),
        ThermoColumn::Time => "time".into(),
        ThermoColumn::Pe => "pe".into(),
        ThermoColumn::Work => "work".into(),
        ThermoColumn::ExternalForce { name, axis } => format!("f{}/{name}", ["x", "y", "z"][*axis]),
        ThermoColumn::ExternalEnergy(name) => format!("pe/{name}"),
        ThermoColumn::PeOf(k) => format!("pe/{}", REGISTRY[*k].name()),
        ThermoColumn::Fmax => "fmax".into(),
        ThermoColumn::Fnorm => "fnorm".into(),
        ThermoColumn::Press => "press".into(),
        ThermoColumn::Pressure(k) => ["pxx", "pyy", "pzz", "pxy", "pxz", "pyz"][*k].into(),
        ThermoColumn::Nbuild => "nbuild".into(),
        ThermoColumn::Events(kind) => format!("{}s", kind.name()),
        ThermoColumn::Bound(t) => format!("nbound/{}", model.bond_types[*t].label.text),
        ThermoColumn::Tension(t) => format!("tension/{}", model.bond_types[*t].label.text),
        ThermoColumn::SolverIterations => "solver_iterations".into(),
        ThermoColumn::SolverResidual => "solver_residual".into(),
        ThermoColumn::ConstraintTension(t) => format!("ctension/{}", model.bond_types[*t].label.text),
        ThermoColumn::BodyVolume(t) => format!("volume/{}", model.body_type_names[*t]),
        ThermoColumn::BodyArea(t) => format!("area/{}", model.body_type_names[*t]),
        ThermoColumn::MinDistance => "mindist".into(),
        ThermoColumn::ContactClamps => "nclamp".into(),
        ThermoColumn::PlaneTension { axis, pos } => format!("planetension/{}/{pos}", ["x", "y", "z"][*axis]),
        ThermoColumn::CorticalTension(t) => format!("gamma/{}", model.body_type_names[*t]),
        ThermoColumn::EndToEnd(t) => format!("e2e/{}", model.bond_types[*t].label.text),
        ThermoColumn::TangentCorrelation { bond_type, lag } => format!("tcorr/{}/{lag}", model.bond_types[*bond_type].label.text),
        ThermoColumn::Fracture { bond_type, quantity } => {
            format!("fracture/{}/{}", model.bond_types[*bond_type].label.text, quantity.name())
        }
        ThermoColumn::Group { group, quantity } => format!("{}/{}", quantity.prefix(), group.name),
        ThermoColumn::Clustering { bond_type, a, b } => {
            format!("clustering/{}/{}/{}", model.bond_types[*bond_type].label.text, a.name, b.name)
        }
        ThermoColumn::IndenterLoad(name) => format!("load/{name}"),
        ThermoColumn::IndenterDepth(name) => format!("depth/{name}"),
    }
}

pub fn column_unit(c: &ThermoColumn, units: UnitSystem) -> &'static str {
    match c {
        ThermoColumn::Step
        | ThermoColumn::Nbuild
        | ThermoColumn::Events(_)
        | ThermoColumn::Bound(_)
        | ThermoColumn::SolverIterations
        | ThermoColumn::SolverResidual
        | ThermoColumn::ContactClamps
        | ThermoColumn::TangentCorrelation { .. }
        | ThermoColumn::Fracture { .. }
        | ThermoColumn::Clustering { .. } => "-",
        ThermoColumn::MinDistance => units.label(Dim::Length),
        ThermoColumn::Tension(_) | ThermoColumn::ConstraintTension(_) | ThermoColumn::PlaneTension { .. } => units.label(Dim::Force),
        ThermoColumn::CorticalTension(_) => units.label(Dim::Tension),
        ThermoColumn::Group { quantity, .. } => units.label(quantity.dim()),
        ThermoColumn::EndToEnd(_) => units.label(Dim::Length),
        ThermoColumn::ExternalForce { .. } | ThermoColumn::IndenterLoad(_) => units.label(Dim::Force),
        ThermoColumn::IndenterDepth(_) => units.label(Dim::Length),
        ThermoColumn::Time => units.label(Dim::Time),
        ThermoColumn::Pe | ThermoColumn::PeOf(_) | ThermoColumn::Work | ThermoColumn::ExternalEnergy(_) => units.label(Dim::Energy),
        ThermoColumn::Fmax | ThermoColumn::Fnorm => units.label(Dim::Force),
        ThermoColumn::Press | ThermoColumn::Pressure(_) => units.label(Dim::Pressure),
        ThermoColumn::BodyVolume(_) => units.label(Dim::Volume),
        ThermoColumn::BodyArea(_) => units.label(Dim::Area),
    }
}

/// Sum over the bodies of type `body_type` of `pick((volume, area))`.
fn body_sum(t: &ThermoInputs, body_type: usize, pick: impl Fn((f64, f64)) -> f64) -> f64 {
    let images = t.sim_box.images();
    (0..t.model.bodies.len())
        .filter(|&b| t.model.bodies[b].body_type as usize == body_type)
        .map(|b| pick(t.model.body_volume_and_area(b, &t.state.positions, &images)))
        .sum()
}

/// A column's value; integers are returned as exact f64.
pub fn column_value(c: &ThermoColumn, t: &ThermoInputs) -> f64 {
    let volume = t.sim_box.volume();
    let ideal = t.model.len() as f64 * t.context.kt / volume;
    let w = &t.forces.virial;
    match c {
        ThermoColumn::Step => t.context.step as f64,
        ThermoColumn::Time => t.context.time,
        ThermoColumn::Pe => t.forces.total_energy() + constant_force_work(t),
        ThermoColumn::Work => constant_force_work(t),
        ThermoColumn::ExternalForce { name, axis } => external_sums(t, name).0[*axis],
        ThermoColumn::ExternalEnergy(name) => external_sums(t, name).1,
        ThermoColumn::PeOf(k) => t.forces.energy_by_interaction[*k],
        ThermoColumn::Fmax => t.forces.max_force().0,
        ThermoColumn::Fnorm => t.forces.forces.iter().map(|f| f.length_squared()).sum::<f64>().sqrt(),
        ThermoColumn::Press => ideal + (w[0] + w[1] + w[2]) / (3.0 * volume),
        ThermoColumn::Pressure(k) => (if *k < 3 { ideal } else { 0.0 }) + w[*k] / volume,
        ThermoColumn::Nbuild => t.backend.neighbor_builds() as f64,
        ThermoColumn::Events(kind) => t.kinetics.count(*kind) as f64,
        ThermoColumn::Bound(ty) => bonds_of_type(t, *ty).count() as f64,
        ThermoColumn::Tension(ty) => {
            // The backend keeps per-bond tensions only for kinetic bonds; compute them otherwise.
            let (bond_tension, _) = t.backend.bond_tension_and_length();
            if bond_tension.len() == t.model.bonds.len() {
                bonds_of_type(t, *ty).map(|b| bond_tension[b]).sum()
            } else {
                let (tension, _) = t.backend.bond_tensions_at(t.model, t.state, t.sim_box);
                bonds_of_type(t, *ty).map(|b| tension[b]).sum()
            }
        }
        ThermoColumn::SolverIterations => t.solve.iterations as f64,
        ThermoColumn::SolverResidual => t.solve.relative_residual,
        ThermoColumn::ConstraintTension(ty) => {
            let c = t.constraints;
            c.list.iter().zip(&c.tension).filter(|(k, _)| t.model.bond_type[k.bond] as usize == *ty).map(|(_, tension)| tension).sum()
        }
        ThermoColumn::BodyVolume(k) => body_sum(t, *k, |(v, _)| v),
        ThermoColumn::BodyArea(k) => body_sum(t, *k, |(_, a)| a),
        ThermoColumn::MinDistance => t.backend.min_contact_distance(),
        ThermoColumn::ContactClamps => t.contact_clamps as f64,
        ThermoColumn::PlaneTension { axis, pos } => planes::plane_tension(t.backend, t.model, t.state, t.sim_box, *axis, *pos),
        ThermoColumn::CorticalTension(k) => planes::cortical_tension(t.backend, t.model, t.state, t.sim_box, *k),
        ThermoColumn::EndToEnd(ty) => filaments::end_to_end(&filaments::chains(t.model, *ty), &t.state.positions, t.sim_box),
        ThermoColumn::TangentCorrelation { bond_type, lag } => {
            filaments::tangent_correlation(&filaments::chains(t.model, *bond_type), &t.state.positions, t.sim_box, *lag)
        }
        ThermoColumn::Fracture { bond_type, quantity } => {
            fracture::fracture(t.model, t.state.bonds.as_ref().map(|s| s.bound.as_slice()), *bond_type).value(*quantity)
        }
        ThermoColumn::Group { group, quantity } => group_value(t, &group.members, *quantity),
        ThermoColumn::Clustering { bond_type, a, b } => clustering::ratio(&clustering::profile(
            t.model,
            t.state.bonds.as_ref().map(|s| s.bound.as_slice()),
            t.state,
            t.sim_box,
            *bond_type,
            &a.members,
            &b.members,
        )),
        ThermoColumn::IndenterLoad(name) => indenter_load(t.model, t.state, t.sim_box, name).map_or(f64::NAN, |(load, _)| load),
        ThermoColumn::IndenterDepth(name) => indenter_load(t.model, t.state, t.sim_box, name).map_or(f64::NAN, |(_, depth)| depth),
    }
}

/// A group column's value over the particles `members`.
fn group_value(t: &ThermoInputs, members: &[u32], quantity: GroupQuantity) -> f64 {
    let unwrapped = |i: u32, axis: usize| t.sim_box.unwrap(t.state.positions[i as usize], t.state.images[i as usize])[axis];
    match quantity {
        GroupQuantity::Force(axis) => members.iter().map(|&i| t.forces.forces[i as usize][axis]).sum(),
        GroupQuantity::Position(axis) => members.iter().map(|&i| unwrapped(i, axis)).sum::<f64>() / members.len() as f64,
        GroupQuantity::Span(axis) => {
            let (low, high) = members.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(low, high), &i| {
                let x = unwrapped(i, axis);
                (low.min(x), high.max(x))
            });
            high - low
        }
        GroupQuantity::ForceMagnitudes => members.iter().map(|&i| t.forces.forces[i as usize].length()).sum(),
        GroupQuantity::HullArea => {
            let points: Vec<glam::DVec2> = members.iter().map(|&i| DVec2::new(unwrapped(i, 0), unwrapped(i, 1))).collect();
            hull_area(points)
        }
    }
}

/// Area of the convex hull of `points` (Andrew's monotone chain, then the
/// shoelace formula); 0 for fewer than three points or collinear ones.
fn hull_area(mut points: Vec<DVec2>) -> f64 {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return 0.0;
    }
    let turn = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * points.len());
    for pass in [points.as_slice(), &points.iter().rev().copied().collect::<Vec<_>>()] {
        let start = hull.len();
        for &p in pass {
            while hull.len() >= start + 2 && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    let n = hull.len();
    (0..n).map(|k| hull[k].perp_dot(hull[(k + 1) % n])).sum::<f64>().abs() / 2.0
}

/// Σ F·x of the `constant_force` externals: minus their energy.
fn constant_force_work(t: &ThermoInputs) -> f64 {
    let k = REGISTRY.iter().position(|i| i.name() == "constant_force").expect("registered");
    -t.forces.energy_by_interaction.get(k).copied().unwrap_or(0.0)
}

/// Summed force and energy of the active external `name` (zero once it is removed).
fn external_sums(t: &ThermoInputs, name: &str) -> (glam::DVec3, f64) {
    let Some(external) = t.model.externals.iter().find(|e| e.term.label.text == name) else { return (glam::DVec3::ZERO, 0.0) };
    crate::backend::external_field(external, t.state, t.sim_box)
        .fold((glam::DVec3::ZERO, 0.0), |(f, e), (_, field)| (f + field.force, e + field.energy))
}

/// Indices of the bound bonds of a bond type.
fn bonds_of_type<'a>(t: &'a ThermoInputs, ty: usize) -> impl Iterator<Item = usize> + 'a {
    (0..t.model.bonds.len()).filter(move |&b| t.model.bond_type[b] as usize == ty && t.state.bonds.as_ref().is_none_or(|s| s.bound[b]))
}

fn is_integer(c: &ThermoColumn) -> bool {
    if let ThermoColumn::Fracture { quantity, .. } = c {
        return quantity.is_integer();
    }
    matches!(
        c,
        ThermoColumn::Step
            | ThermoColumn::Nbuild
            | ThermoColumn::Events(_)
            | ThermoColumn::Bound(_)
            | ThermoColumn::SolverIterations
            | ThermoColumn::ContactClamps
    )
}

/// Thermo state of a running deck.
pub struct Thermo {
    pub every: u64,
    columns: Vec<ThermoColumn>,
    /// Header name of each column.
    pub(crate) labels: Vec<String>,
    pub units: UnitSystem,
    /// The CSV file and its path (for error messages).
    file: Option<(RecordFile, PathBuf)>,
    file_header_written: bool,
    /// Whether rows are kept in `log` (the Python API's `thermo()`).
    pub(crate) record: bool,
    /// The rows since recording began or the columns last changed.
    pub(crate) log: Vec<Vec<f64>>,
}

/// An error writing the thermo CSV: its path and the cause.
pub type FileError = (PathBuf, std::io::Error);

/// Minimum column width on stdout; longer names widen their column.
const WIDTH: usize = 14;

impl Thermo {
    pub fn new(model: &crate::system::Model) -> Self {
        let mut thermo = Self {
            every: 0,
            columns: Vec::new(),
            labels: Vec::new(),
            units: model.units,
            file: None,
            file_header_written: false,
            record: false,
            log: Vec::new(),
        };
        thermo.set_columns(vec![ThermoColumn::Step, ThermoColumn::Time, ThermoColumn::Pe, ThermoColumn::Fmax, ThermoColumn::Press], model);
        thermo
    }

    /// New columns; a CSV file gets a new header line before its next row.
    pub fn set_columns(&mut self, columns: Vec<ThermoColumn>, model: &crate::system::Model) {
        if columns != self.columns {
            self.file_header_written = false;
            self.log.clear();
        }
        self.labels = columns.iter().map(|c| column_label(c, model)).collect();
        self.columns = columns;
    }

    fn width(&self, k: usize) -> usize {
        WIDTH.max(self.labels[k].chars().count() + 2)
    }

    pub fn set_file(&mut self, file: File, path: PathBuf) -> Result<(), FileError> {
        self.close()?;
        self.file = Some((RecordFile::new(file), path));
        self.file_header_written = false;
        Ok(())
    }

    /// The two header lines (names, then units) for stdout.
    pub fn header(&self) -> String {
        let names: String = (0..self.columns.len()).map(|k| format!("{:>w$}", self.labels[k], w = self.width(k))).collect();
        let units: String = (0..self.columns.len())
            .map(|k| format!("{:>w$}", format!("[{}]", column_unit(&self.columns[k], self.units)), w = self.width(k)))
            .collect();
        format!("{names}\n{units}")
    }

    /// The values of a row, in column order.
    pub fn values(&self, inputs: &ThermoInputs) -> Vec<f64> {
        self.columns.iter().map(|c| column_value(c, inputs)).collect()
    }

    /// A row of [`values`](Self::values) for stdout; also appended to the
    /// CSV file when one is set, and flushed: the file holds every row
    /// printed so far, each whole, whenever the run is killed. Rows are also
    /// kept in memory when recording.
    pub fn row(&mut self, values: &[f64]) -> Result<String, FileError> {
        if self.record {
            self.log.push(values.to_vec());
        }
        let line: String = (0..self.columns.len())
            .map(|k| {
                let w = self.width(k);
                if is_integer(&self.columns[k]) {
                    format!("{:>w$}", values[k] as u64)
                } else {
                    format!("{:>w$.6e}", values[k])
                }
            })
            .collect();
        if let Some((file, path)) = &mut self.file {
            let mut write = || -> std::io::Result<()> {
                if !self.file_header_written {
                    let header: Vec<String> =
                        self.columns.iter().zip(&self.labels).map(|(c, l)| format!("{l}[{}]", column_unit(c, self.units))).collect();
                    writeln!(file, "{}", header.join(","))?;
                    self.file_header_written = true;
                }
                let fields: Vec<String> = self
                    .columns
                    .iter()
                    .zip(values)
                    .map(|(c, v)| if is_integer(c) { format!("{}", *v as u64) } else { format!("{v:e}") })
                    .collect();
                writeln!(file, "{}", fields.join(","))?;
                // The row goes to the file whole.
                file.commit()
            };
            write().map_err(|e| (path.clone(), e))?;
        }
        Ok(line)
    }

    pub fn close(&mut self) -> Result<(), FileError> {
        if let Some((mut file, path)) = self.file.take() {
            file.finish().map_err(|e| (path, e))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_area_of_points_inside_and_on_the_edges_of_a_rectangle_is_the_rectangle() {
        let mut points: Vec<DVec2> = (0..=6).flat_map(|i| (0..=4).map(move |j| DVec2::new(i as f64 * 0.5, j as f64 * 0.25))).collect();
        points.reverse();
        assert!((hull_area(points) - 3.0).abs() < 1e-12);
        let disc: Vec<DVec2> = (0..1000).map(|k| DVec2::from_angle(k as f64 * 0.001 * std::f64::consts::TAU) * 2.0).collect();
        assert!((hull_area(disc) / (std::f64::consts::PI * 4.0) - 1.0).abs() < 1e-4);
        assert_eq!(hull_area(vec![DVec2::ZERO, DVec2::X, DVec2::X * 2.0]), 0.0);
        assert_eq!(hull_area(vec![DVec2::ZERO, DVec2::Y]), 0.0);
    }
}
