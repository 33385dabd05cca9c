//! Trajectory formats read back by the programs users open them with: the
//! extended XYZ by ASE (`ase.io.read`) and OVITO (`ovito.io.import_file`),
//! the DCD by MDAnalysis (positions and times), the LAMMPS dump by ASE and
//! OVITO, each compared with the LAMMPS dump of the same frames (text,
//! bit-exact); the LAMMPS dump's `element` column (the chemical symbol
//! standing for each type); the MCAP's compressed chunks and protobuf scene
//! (box, walls, bound bonds only), and its own protobuf channels as the
//! Python `mcap-protobuf-support` decoder reads them from their descriptors.
//!
//! ASE, MDAnalysis, OVITO and the mcap libraries come from the reference venv (`scripts/reference-venv`,
//! which `scripts/test-all` creates before the tests run). Where it is absent
//! the reader checks print why and pass without reading.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Command;

use crate::common::{random_case, Case};
use prost::Message as _;
use serde_json::Value;

/// The reference venv's Python: `$CELLMD_VENV` or `~/.cache/cellmd/reference-venv`.
fn reference_python() -> Option<PathBuf> {
    let venv = match std::env::var_os("CELLMD_VENV") {
        Some(v) => PathBuf::from(v),
        None => PathBuf::from(std::env::var_os("HOME")?).join(".cache/cellmd/reference-venv"),
    };
    let python = venv.join("bin/python");
    python.is_file().then_some(python)
}

/// Runs `script` (Python) with `args`; returns its stdout parsed as JSON.
fn python_json(python: &PathBuf, script: &str, args: &[&std::path::Path]) -> Value {
    let out = Command::new(python).arg("-c").arg(script).args(args).output().unwrap();
    assert!(out.status.success(), "python failed:\n{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// One LAMMPS dump frame: box bounds and rows by column name, in id order.
struct DumpFrame {
    step: u64,
    bounds: [[f64; 2]; 3],
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl DumpFrame {
    fn column(&self, name: &str) -> Vec<&str> {
        let k = self.header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
        self.rows.iter().map(|r| r[k].as_str()).collect()
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        let (x, y, z) = (self.column("x"), self.column("y"), self.column("z"));
        (0..self.rows.len()).map(|i| [x[i], y[i], z[i]].map(|v| v.parse().unwrap())).collect()
    }
}

fn read_dump(path: &std::path::Path) -> Vec<DumpFrame> {
    let text = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut frames = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        assert_eq!(lines[k], "ITEM: TIMESTEP");
        let n: usize = lines[k + 3].parse().unwrap();
        let bounds = [0, 1, 2].map(|a| {
            let v: Vec<f64> = lines[k + 5 + a].split(' ').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1]]
        });
        frames.push(DumpFrame {
            step: lines[k + 1].parse().unwrap(),
            bounds,
            header: lines[k + 8].strip_prefix("ITEM: ATOMS ").unwrap().split(' ').map(String::from).collect(),
            rows: lines[k + 9..k + 9 + n].iter().map(|l| l.split(' ').map(String::from).collect()).collect(),
        });
        k += 9 + n;
    }
    frames
}

/// 400 particles of types `a` and `b` (soft pairs only) in a periodic box of
/// edge 8, with a wall, dumped every 10 steps to every format.
fn dumped_case() -> Case {
    let case = random_case(true, "");
    let ff = "particle a drag 1\nparticle b drag 2\nbond s harmonic k 2 r0 0.5\nangle t cosine_angle K 0.3\n\
              pair a a soft A 1 rc 0.9\npair a b soft A 1 rc 0.7\n";
    std::fs::write(case.path("f.ff"), ff).unwrap();
    let body = "temperature 1\ntimestep 0.001\nseed 3\n\
                external floor all wall nz 1 d 1 k 5\ndump l every 10 lammps t.lammpstrj\ndump x every 10 xyz t.xyz\n\
                dump d every 10 dcd t.dcd\ndump m every 10 mcap t.mcap\nrun 30\n";
    let deck = std::fs::read_to_string(case.path("deck.in")).unwrap() + body;
    std::fs::write(case.path("deck.in"), deck).unwrap();
    case.run();
    case
}

const ASE_READ: &str = r#"
import json, sys
import ase.io
frames = ase.io.read(sys.argv[1], index=":", format="extxyz")
print(json.dumps([{
    "symbols": a.get_chemical_symbols(),
    "type_name": [str(t) for t in a.arrays["type_name"]],
    "id": [int(i) for i in a.arrays["id"]],
    "positions": a.get_positions().tolist(),
    "cell": a.cell.array.tolist(),
    "pbc": [bool(p) for p in a.pbc],
    "step": int(a.info["Step"]),
} for a in frames]))
"#;

const MDANALYSIS_READ: &str = r#"
import json, sys, warnings
warnings.simplefilter("ignore")
from MDAnalysis.coordinates.DCD import DCDReader
r = DCDReader(sys.argv[1])
print(json.dumps({
    "n_atoms": r.n_atoms,
    "dt": float(r.dt),
    "frames": [{"positions": [[float(v) for v in p] for p in ts.positions], "dimensions": [float(v) for v in ts.dimensions],
                "time": float(ts.time)} for ts in r],
}))
"#;

/// ASE's LAMMPS-dump reader: chemical symbols and positions per frame.
const ASE_READ_DUMP: &str = r#"
import json, sys
import ase.io
frames = ase.io.read(sys.argv[1], index=":", format="lammps-dump-text")
print(json.dumps([{"symbols": a.get_chemical_symbols(), "positions": a.get_positions().tolist()} for a in frames]))
"#;

/// OVITO's importer: the particle type names and positions per frame.
const OVITO_READ: &str = r#"
import json, sys
from ovito.io import import_file
pipeline = import_file(sys.argv[1])
out = []
for frame in range(pipeline.num_frames):
    data = pipeline.compute(frame)
    types = data.particles.particle_types
    names = {t.id: t.name for t in types.types}
    out.append({"types": [names[int(t)] for t in types[...]], "positions": data.particles.positions[...].tolist(),
                "ids": [int(i) for i in data.particles.identifiers[...]]})
print(json.dumps(out))
"#;

/// Whether the reference venv has OVITO (added to it later than the others).
fn has_ovito(python: &PathBuf) -> bool {
    Command::new(python).args(["-c", "import ovito"]).output().is_ok_and(|o| o.status.success())
}

/// The dump's `element` column holds the chemical symbol standing for each
/// type (type 1 → H, 2 → He), which ASE can map.
#[test]
fn the_lammps_dump_writes_the_element_standing_for_each_type() {
    let case = dumped_case();
    let frames = read_dump(&case.path("t.lammpstrj"));
    assert_eq!(frames.iter().map(|f| f.step).collect::<Vec<_>>(), [0, 10, 20, 30]);
    for f in &frames {
        assert_eq!(f.header.join(" "), "id type element x y z ix iy iz");
        for (ty, element) in f.column("type").iter().zip(f.column("element")) {
            assert_eq!(element, ["H", "He"][ty.parse::<usize>().unwrap() - 1]);
        }
    }
}

/// The type names of the 400 particles by id, from the dump's type numbers
/// (`a` is type 1, `b` type 2: the force field's order).
fn names_by_id(dump: &DumpFrame) -> BTreeMap<u64, &'static str> {
    dump.column("id").iter().zip(dump.column("type")).map(|(id, t)| (id.parse().unwrap(), if t == "1" { "a" } else { "b" })).collect()
}

/// ASE reads cellmd's LAMMPS dump (it failed on type names in `element`):
/// every frame, H for type 1 and He for type 2, positions bit for bit.
#[test]
fn ase_reads_the_lammps_dump() {
    let Some(python) = reference_python() else {
        eprintln!("SKIPPED: no reference venv (run `bash scripts/reference-venv`); ASE cannot read the LAMMPS dump");
        return;
    };
    let case = dumped_case();
    let dump = read_dump(&case.path("t.lammpstrj"));
    let frames = python_json(&python, ASE_READ_DUMP, &[&case.path("t.lammpstrj")]);
    let frames = frames.as_array().unwrap();
    assert_eq!(frames.len(), dump.len());
    for (frame, want) in frames.iter().zip(&dump) {
        let symbols: Vec<String> = serde_json::from_value(frame["symbols"].clone()).unwrap();
        let positions: Vec<[f64; 3]> = serde_json::from_value(frame["positions"].clone()).unwrap();
        // ASE sorts by id, as the dump is.
        let want_symbols: Vec<&str> = want.column("type").iter().map(|t| if *t == "1" { "H" } else { "He" }).collect();
        assert_eq!(symbols, want_symbols);
        assert!(want_symbols.contains(&"H") && want_symbols.contains(&"He"));
        for (got, x) in positions.iter().zip(want.positions()) {
            assert_eq!(got.map(f64::to_bits), x.map(f64::to_bits));
        }
    }
}

/// OVITO names the XYZ's particle types after the type names (`a`, `b`,
/// not H/He) and the dump's after their elements; positions to the last
/// bit but one (OVITO's parser rounds some 17-digit numbers one ulp off).
#[test]
fn ovito_reads_the_xyz_with_type_names_and_the_lammps_dump() {
    let Some(python) = reference_python().filter(has_ovito) else {
        eprintln!("SKIPPED: no reference venv with OVITO (run `bash scripts/reference-venv`); OVITO cannot read the XYZ and dump");
        return;
    };
    let case = dumped_case();
    let dump = read_dump(&case.path("t.lammpstrj"));
    let xyz = python_json(&python, OVITO_READ, &[&case.path("t.xyz")]);
    let ovito_dump = python_json(&python, OVITO_READ, &[&case.path("t.lammpstrj")]);
    let (xyz, ovito_dump) = (xyz.as_array().unwrap(), ovito_dump.as_array().unwrap());
    assert_eq!((xyz.len(), ovito_dump.len()), (dump.len(), dump.len()));
    for ((from_xyz, from_dump), want) in xyz.iter().zip(ovito_dump).zip(&dump) {
        let names = names_by_id(want);
        let by_id: BTreeMap<u64, [f64; 3]> = want.column("id").iter().map(|id| id.parse().unwrap()).zip(want.positions()).collect();
        for (from, names) in
            [(from_xyz, names.clone()), (from_dump, names.iter().map(|(&id, &n)| (id, if n == "a" { "H" } else { "He" })).collect())]
        {
            let types: Vec<String> = serde_json::from_value(from["types"].clone()).unwrap();
            let positions: Vec<[f64; 3]> = serde_json::from_value(from["positions"].clone()).unwrap();
            let ids: Vec<u64> = serde_json::from_value(from["ids"].clone()).unwrap();
            assert_eq!(ids.len(), by_id.len());
            for ((id, t), x) in ids.iter().zip(&types).zip(&positions) {
                assert_eq!(t, names[id], "id {id}");
                // OVITO's number parser is not correctly rounded: it reads the
                // `1.4036974322645301` written by cellmd as 1.40369743226453, one ulp below.
                let ulps = (0..3).map(|a| x[a].to_bits().abs_diff(by_id[id][a].to_bits())).max().unwrap();
                assert!(ulps <= 1, "id {id}: OVITO read {x:?}, the file holds {:?}", by_id[id]);
            }
        }
    }
}

#[test]
fn ase_reads_the_extended_xyz_with_elements_and_type_names() {
    let Some(python) = reference_python() else {
        eprintln!("SKIPPED: no reference venv (run `bash scripts/reference-venv`); ASE cannot read the XYZ");
        return;
    };
    let case = dumped_case();
    let dump = read_dump(&case.path("t.lammpstrj"));
    let frames = python_json(&python, ASE_READ, &[&case.path("t.xyz")]);
    let frames = frames.as_array().unwrap();
    assert_eq!(frames.len(), dump.len());
    for (frame, want) in frames.iter().zip(&dump) {
        assert_eq!(frame["step"].as_u64().unwrap(), want.step);
        assert_eq!(frame["pbc"], serde_json::json!([true, true, true]));
        let cell: Vec<Vec<f64>> = serde_json::from_value(frame["cell"].clone()).unwrap();
        for (a, row) in cell.iter().enumerate() {
            let edge = want.bounds[a][1] - want.bounds[a][0];
            for (b, &value) in row.iter().enumerate() {
                assert_eq!(value, if a == b { edge } else { 0.0 });
            }
        }
        // ASE keeps the file's (internal) order; the dump is sorted by id.
        let by_id: BTreeMap<u64, ([f64; 3], &str)> = (want.column("id").iter().zip(want.positions()).zip(want.column("element")))
            .map(|((id, x), element)| (id.parse().unwrap(), (x, element)))
            .collect();
        let ids: Vec<u64> = serde_json::from_value(frame["id"].clone()).unwrap();
        let positions: Vec<[f64; 3]> = serde_json::from_value(frame["positions"].clone()).unwrap();
        let symbols: Vec<String> = serde_json::from_value(frame["symbols"].clone()).unwrap();
        let type_names: Vec<String> = serde_json::from_value(frame["type_name"].clone()).unwrap();
        assert_eq!(ids.len(), by_id.len());
        for i in 0..ids.len() {
            let (x, element) = by_id[&ids[i]];
            assert_eq!(positions[i].map(f64::to_bits), x.map(f64::to_bits), "id {}", ids[i]);
            assert_eq!(type_names[i], if element == "H" { "a" } else { "b" });
            assert_eq!(symbols[i], element);
        }
    }
}

#[test]
fn mdanalysis_reads_the_dcd_in_id_order_with_its_times() {
    let Some(python) = reference_python() else {
        eprintln!("SKIPPED: no reference venv (run `bash scripts/reference-venv`); MDAnalysis cannot read the DCD");
        return;
    };
    let case = dumped_case();
    let dump = read_dump(&case.path("t.lammpstrj"));
    let read = python_json(&python, MDANALYSIS_READ, &[&case.path("t.dcd")]);
    assert_eq!(read["n_atoms"], 400);
    // Frames every 10 steps of 0.001: MDAnalysis reads the interval as 0.01
    // (the deck's number; DELTA is an f32 in AKMA units, so to f32 precision).
    let dt = read["dt"].as_f64().unwrap();
    assert!((dt - 0.01).abs() <= 1e-7 * 0.01, "MDAnalysis reads dt = {dt}, expected 0.01");
    let frames = read["frames"].as_array().unwrap();
    assert_eq!(frames.len(), dump.len());
    for (frame, want) in frames.iter().zip(&dump) {
        let time = frame["time"].as_f64().unwrap();
        let expected = want.step as f64 * 0.001;
        assert!((time - expected).abs() <= 1e-7 * 0.03, "frame at step {}: time {time}, expected {expected}", want.step);
        let dimensions: Vec<f64> = serde_json::from_value(frame["dimensions"].clone()).unwrap();
        assert_eq!(dimensions, [8.0, 8.0, 8.0, 90.0, 90.0, 90.0]);
        let positions: Vec<[f64; 3]> = serde_json::from_value(frame["positions"].clone()).unwrap();
        // f32 coordinates: the dump's f64 rounded once.
        for (got, x) in positions.iter().zip(want.positions()) {
            assert_eq!(*got, x.map(|v| v as f32 as f64));
        }
    }
}

const MCAP_PROTOBUF_READ: &str = r#"
import json, sys
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

def plain(message):
    out = {}
    for f in message.DESCRIPTOR.fields:
        value = getattr(message, f.name)
        repeated = f.is_repeated if hasattr(f, "is_repeated") else f.label == f.LABEL_REPEATED
        if repeated:
            out[f.name] = [plain(v) if f.message_type else v for v in value]
        else:
            out[f.name] = plain(value) if f.message_type else value
    return out

with open(sys.argv[1], "rb") as fh:
    reader = make_reader(fh, decoder_factories=[DecoderFactory()])
    print(json.dumps([[channel.topic, schema.name, plain(decoded)]
                      for schema, channel, _, decoded in reader.iter_decoded_messages()
                      if channel.topic.startswith("/cellmd/")]))
"#;

/// cellmd's own MCAP channels are typed protobuf: the Python decoder Foxglove
/// publishes builds the message classes from the file's descriptor sets alone
/// and reads every message (topology, frames, bond states and bond events)
/// to the same values cellmd's reader gets, bit for bit.
#[test]
fn python_reads_the_mcap_protobuf_channels_from_their_descriptors() {
    let Some(python) = reference_python() else {
        eprintln!("SKIPPED: no reference venv (run `bash scripts/reference-venv`); Python cannot read the MCAP");
        return;
    };
    let case = random_case(true, "");
    // Stretched slip bonds that rebind: bond events in the first steps.
    let ff = "particle a drag 1\nparticle b drag 2\n\
              bond s harmonic k 2 r0 0.5 kinetics slip k0 2 x_beta 0.2 kinetics rebind k_on 3 capture 2\n\
              angle t cosine_angle K 0.3\npair a a soft A 1 rc 0.9\n";
    std::fs::write(case.path("f.ff"), ff).unwrap();
    let deck = std::fs::read_to_string(case.path("deck.in")).unwrap()
        + "temperature 1\ntimestep 0.001\nseed 3\ndump m every 10 mcap t.mcap\nrun 30\n";
    std::fs::write(case.path("deck.in"), deck).unwrap();
    case.run();
    let bytes = std::fs::read(case.path("t.mcap")).unwrap();
    let ours: Vec<Value> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic.starts_with("/cellmd/"))
        .map(|m| {
            assert_eq!(m.channel.message_encoding, "protobuf", "{}", m.channel.topic);
            let mut json = cellmd::output::mcap_messages::message_json(&m).unwrap();
            // The JSON form nests bonds, angles and triangles; protobuf keeps them flat.
            for key in ["bonds", "angles", "triangles"] {
                if let Some(nested) = json.get(key).and_then(Value::as_array) {
                    json[key] = nested.iter().flat_map(|v| v.as_array().unwrap().clone()).collect();
                }
            }
            serde_json::json!([m.channel.topic, m.channel.schema.as_ref().unwrap().name, json])
        })
        .collect();
    let theirs = python_json(&python, MCAP_PROTOBUF_READ, &[&case.path("t.mcap")]);
    let theirs = theirs.as_array().unwrap();
    let count = |topic: &str| ours.iter().filter(|m| m[0] == topic).count();
    assert_eq!((count("/cellmd/topology"), count("/cellmd/frame")), (1, 4));
    assert!(count("/cellmd/events") > 0 && count("/cellmd/bond_state") > 1, "no bond events to read");
    assert_eq!(theirs.len(), ours.len());
    for (theirs, ours) in theirs.iter().zip(&ours) {
        assert_eq!(theirs, ours);
    }
}

/// The last `/scene` of an MCAP, decoded from protobuf.
fn last_scene(path: &std::path::Path) -> foxglove::schemas::SceneUpdate {
    let bytes = std::fs::read(path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert!(summary.chunk_indexes.iter().all(|c| c.compression == "zstd"));
    let scenes: Vec<_> = mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()).filter(|m| m.channel.topic == "/scene").collect();
    let last = scenes.last().expect("a scene");
    assert_eq!(last.channel.message_encoding, "protobuf");
    foxglove::schemas::SceneUpdate::decode(&last.data[..]).unwrap()
}

#[test]
fn the_mcap_scene_draws_the_box_and_the_wall() {
    let case = dumped_case();
    let scene = last_scene(&case.path("t.mcap"));
    let frame_box = scene.entities.iter().find(|e| e.id == "box").unwrap();
    assert_eq!(frame_box.lines[0].points.len(), 24);
    assert_eq!(frame_box.triangles.len(), 1, "one wall");
    assert!(frame_box.triangles[0].points.iter().all(|p| p.z == 1.0), "the wall is the plane z = 1");
    let particles = scene.entities.iter().find(|e| e.id == "particles").unwrap();
    assert_eq!(particles.spheres.len(), 400);
    assert_eq!(particles.lines[0].points.len(), 2 * 200);
}

/// Slip bonds break during the run; the scene draws the bound ones only.
#[test]
fn the_mcap_scene_leaves_broken_bonds_out() {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for g in 0..50 {
        top += &format!("{} a {} 0 0\n{} a {} 0 1.2\n", 2 * g + 1, 3 * g, 2 * g + 2, 3 * g);
        bonds += &format!("f {} {}\n", 2 * g + 1, 2 * g + 2);
    }
    let ff = "particle a fixed\nbond f harmonic k 10 r0 1 kinetics slip k0 2 x_beta 0.2\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -10 1000 f y -10 1000 f z -10 1000 f\n\
                temperature 1\ntimestep 0.01\nseed 8\ndump m every 30 mcap t.mcap\nrun 30\n";
    let case = Case::new(&[("t.top", &(top + &bonds)), ("f.ff", ff), ("deck.in", deck)]);
    let sim = case.run();
    let bound = sim.state.bonds.as_ref().unwrap().bound.iter().filter(|&&b| b).count();
    assert!(0 < bound && bound < 50, "{bound} of 50 bonds bound: the test needs some of each");
    let scene = last_scene(&case.path("t.mcap"));
    let particles = scene.entities.iter().find(|e| e.id == "particles").unwrap();
    assert_eq!(particles.lines[0].points.len(), 2 * bound);
    // Every drawn segment is 1.2 long along z: a bound pair, never two groups joined.
    for s in particles.lines[0].points.chunks(2) {
        assert_eq!((s[0].x, s[0].y, s[1].x, s[1].y), (s[1].x, s[1].y, s[0].x, s[0].y));
        assert!((s[1].z - s[0].z).abs() == 1.2);
    }
}
