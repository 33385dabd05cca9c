use super::*;
use crate::build::testing::{bonds_of, parse};

#[test]
fn a_pair_has_rings_hubs_and_a_network_attached_to_them() {
    let a = CollagenArgs::default();
    let built = collagen(&a).unwrap();
    assert_eq!(collagen(&a).unwrap().text, built.text, "deterministic");
    let top = parse(&built);
    // Hubs and rings first: 2 × 84, the hub at the centre, the ring at R.
    for (c, x) in [(0, -30.0), (1, 30.0)] {
        let hub = top.positions[c * 84];
        assert_eq!(hub, DVec3::new(x, 0.0, 0.0));
        for k in 1..84 {
            assert!(((top.positions[c * 84 + k] - hub).length() - 10.0).abs() < 1e-12);
        }
    }
    assert_eq!(bonds_of(&top, "cortex").count(), 166);
    assert_eq!(bonds_of(&top, "spoke").count(), 166);
    // Flat, inside the rectangle, nothing of the network inside a hole.
    assert!(top.positions.iter().all(|p| p.z == 0.0 && p.x.abs() <= 60.0 && p.y.abs() <= 40.0));
    for p in &top.positions[168..] {
        assert!((p.truncate() - DVec2::new(-30.0, 0.0)).length() > 10.0 - 1e-9);
        assert!((p.truncate() - DVec2::new(30.0, 0.0)).length() > 10.0 - 1e-9);
    }
    // Fibre bonds no longer than the node spacing, each with its own r0;
    // the network is attached to both rings.
    let fibres: Vec<[DVec3; 2]> = bonds_of(&top, "fibre").collect();
    assert!(fibres.len() > 500, "{}", fibres.len());
    assert!(fibres.iter().all(|[x, y]| (*x - *y).length() <= 3.0 + 1e-9));
    assert!(built.text.lines().filter(|l| l.starts_with("fibre ")).all(|l| l.split_whitespace().count() == 4));
    assert!(built.text.lines().filter(|l| l.starts_with("cortex ") || l.starts_with("spoke ")).all(|l| l.split_whitespace().count() == 3));
    for x in [-30.0, 30.0] {
        let touching =
            fibres.iter().filter(|b| b.iter().any(|p| ((p.truncate() - DVec2::new(x, 0.0)).length() - 10.0).abs() < 1e-9)).count();
        assert!(touching >= 10, "{touching} fibres reach the cell at x = {x}");
    }
    // Every network node has at least two bonds or is an anchor at the edge.
    let mut degree = std::collections::HashMap::<u64, usize>::new();
    for line in built.text.lines().filter(|l| l.starts_with("fibre ")) {
        let f: Vec<u64> = line.split_whitespace().skip(1).take(2).map(|v| v.parse().unwrap()).collect();
        *degree.entry(f[0]).or_default() += 1;
        *degree.entry(f[1]).or_default() += 1;
    }
    for line in built.text.lines().filter(|l| l.split_whitespace().nth(1) == Some("node")) {
        let id: u64 = line.split_whitespace().next().unwrap().parse().unwrap();
        assert!(degree.get(&id).copied().unwrap_or(0) >= 2, "{line}");
    }
    for line in built.text.lines().filter(|l| l.split_whitespace().nth(1) == Some("anchor")) {
        let f: Vec<f64> = line.split_whitespace().skip(2).map(|v| v.parse().unwrap()).collect();
        assert!(((f[0].abs() - 60.0).abs() < 1e-9) || ((f[1].abs() - 40.0).abs() < 1e-9), "{line}");
    }
}

#[test]
fn the_density_is_the_fibre_length_per_area() {
    // Long fibres in a big box: the length per area outside the holes
    // follows ρ, less the free ends beyond the last crosslinks.
    let a = CollagenArgs { size: vec![300.0, 300.0], density: 0.3, fibre_length: 30.0, ..CollagenArgs::default() };
    let top = parse(&collagen(&a).unwrap());
    let total: f64 = bonds_of(&top, "fibre").map(|[x, y]| (x - y).length()).sum();
    let density = total / (300.0 * 300.0 - 2.0 * PI * 100.0);
    // Trimmed free ends lose about 2·π/(2ρ)/L = 35 % of a fibre (ends
    // anchored at the edge keep theirs): between 0.55ρ and 0.8ρ.
    assert!(density > 0.55 * 0.3 && density < 0.8 * 0.3, "{density}");
}

#[test]
fn square_and_random_layouts_place_their_cells() {
    let square =
        parse(&collagen(&CollagenArgs { layout: CellLayout::Square, size: vec![120.0, 120.0], ..CollagenArgs::default() }).unwrap());
    let hubs: Vec<DVec3> = (0..4).map(|c| square.positions[c * 84]).collect();
    assert_eq!(hubs[0], DVec3::new(-30.0, -30.0, 0.0));
    assert_eq!(hubs[2], DVec3::new(30.0, 30.0, 0.0));
    let random = |seed| CollagenArgs {
        layout: CellLayout::Random,
        cells: Some(5),
        size: vec![200.0, 200.0],
        common: Common { seed, ..CollagenArgs::default().common },
        ..CollagenArgs::default()
    };
    let top = parse(&collagen(&random(3)).unwrap());
    let hubs: Vec<DVec3> = (0..5).map(|c| top.positions[c * 84]).collect();
    for i in 0..5 {
        assert!(hubs[i].x.abs() <= 100.0 - 13.0 && hubs[i].y.abs() <= 100.0 - 13.0);
        for j in 0..i {
            assert!((hubs[i] - hubs[j]).length() >= 60.0);
        }
    }
    assert_ne!(collagen(&random(4)).unwrap().text, collagen(&random(3)).unwrap().text);
}

#[test]
fn bad_options_say_what_was_expected() {
    let a = CollagenArgs::default();
    let err = |b: CollagenArgs| collagen(&b).unwrap_err();
    assert_eq!(err(CollagenArgs { density: 0.0, ..a.clone() }), "expected --density > 0, found 0");
    assert_eq!(err(CollagenArgs { node_spacing: f64::NAN, ..a.clone() }), "expected --node-spacing > 0, found NaN");
    assert!(err(CollagenArgs { separation: 20.0, ..a.clone() }).starts_with("expected --separation > 2 × --cell-radius + --node-spacing"));
    assert!(err(CollagenArgs { size: vec![70.0, 80.0], ..a.clone() }).starts_with("expected --size to hold every cell"));
    assert_eq!(err(CollagenArgs { ring_nodes: 2, ..a.clone() }), "expected 3 <= --ring-nodes <= 100000, found 2");
    assert_eq!(
        err(CollagenArgs { cells: Some(3), ..a.clone() }),
        "expected --cells only with --layout random (--layout pair places its own)"
    );
    assert_eq!(err(CollagenArgs { layout: CellLayout::Random, ..a.clone() }), "expected --cells N with --layout random");
    assert!(err(CollagenArgs { layout: CellLayout::Random, cells: Some(50), ..a.clone() }).starts_with("expected room for 50 cells"));
    assert!(err(CollagenArgs { density: 100.0, ..a.clone() }).starts_with("expected at most 20000 fibres"));
}
