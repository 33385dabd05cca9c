use super::*;

#[test]
fn crosslinker_types_parse_and_pick_by_fraction() {
    let t: CrosslinkerTypes = "xl_stiff:0.25, xl_soft:0.75".parse().unwrap();
    assert_eq!(t.0, vec![("xl_stiff".into(), 0.25), ("xl_soft".into(), 0.75)]);
    assert_eq!((t.pick(0.1), t.pick(0.3), t.pick(0.999)), (0, 1, 1));
    assert_eq!("xl".parse::<CrosslinkerTypes>().unwrap().0, vec![("xl".into(), 1.0)]);
    assert_eq!("a:2,b:2".parse::<CrosslinkerTypes>().unwrap().0[1].1, 0.5);
    assert!("a:-1".parse::<CrosslinkerTypes>().unwrap_err().contains("expected a fraction >= 0"));
    assert!("a:0".parse::<CrosslinkerTypes>().unwrap_err().contains("summing to more than 0"));
    assert!("a:1,a:1".parse::<CrosslinkerTypes>().unwrap_err().contains("twice"));
    assert!("a:x".parse::<CrosslinkerTypes>().unwrap_err().contains("expected a number"));
}

#[test]
fn draws_are_pure_functions_of_seed_and_counter() {
    let d = Draws::new(7, stream::NETWORK);
    assert_eq!(d.uniform2(3, 1), Draws::new(7, stream::NETWORK).uniform2(3, 1));
    assert_ne!(d.uniform2(3, 1), d.uniform2(4, 1));
    assert_ne!(d.uniform2(3, 1), d.uniform2(3, 2));
    assert_ne!(d.uniform2(3, 1), Draws::new(8, stream::NETWORK).uniform2(3, 1));
    assert!((d.unit_vector(0, 0).length() - 1.0).abs() < 1e-15);
    let q = d.rotation(0, 0);
    assert!((q.length() - 1.0).abs() < 1e-15);
    let picked = d.choose(0, 0, 10, 4);
    assert_eq!(picked.len(), 4);
    assert!(picked.windows(2).all(|w| w[0] < w[1]) && picked.iter().all(|&i| i < 10));
    assert_eq!(d.choose(0, 0, 3, 3), vec![0, 1, 2]);
}

#[test]
fn segmentation_and_its_errors() {
    let c = Chain { length: 2.0, segments: None, segment_length: Some(0.3), ..Chain::default() };
    let (n, ell) = c.segmentation().unwrap();
    assert_eq!(n, 7);
    assert!((ell - 2.0 / 7.0).abs() < 1e-15);
    assert_eq!(Chain { segments: Some(0), ..Chain::default() }.segmentation().unwrap_err(), "expected --segments >= 1, found 0");
    assert_eq!(Chain { length: -1.0, ..Chain::default() }.segmentation().unwrap_err(), "expected --length > 0, found -1");
    assert!(Chain { segments: None, segment_length: Some(-0.1), ..Chain::default() }
        .segmentation()
        .unwrap_err()
        .contains("--segment-length > 0"));
    assert!(Chain { segments: None, ..Chain::default() }.segmentation().unwrap_err().contains("expected --segments N or --segment-length"));
    assert_eq!(wrap(-0.5, 0.0, 10.0), 9.5);
    assert_eq!(wrap(-1e-18, 0.0, 10.0), 0.0);
    assert_eq!(wrap(25.0, 0.0, 10.0), 5.0);
}
