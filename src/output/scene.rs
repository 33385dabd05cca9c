//! The Foxglove 3D scene of an MCAP trajectory: one `foxglove.SceneUpdate`
//! per frame on `/scene`, built once as the `foxglove` crate's protobuf
//! messages and written as protobuf (the default) or, when the deck asks
//! (`encoding json`), as JSON matching [`SCENE_UPDATE_SCHEMA`].
//!
//! # Entities
//!
//! Both replace their previous version each frame (same id, frame `world`):
//!
//! | id | primitives |
//! |---|---|
//! | `particles` | a `SpherePrimitive` per particle (diameter `2·radius` of its type, or `2·DEFAULT_RADIUS` when the radius is 0; colour by type from [`PALETTE`]); one `LinePrimitive` (`LINE_LIST`, 2 px, `scale_invariant`) with a segment per **bound** bond; one `TriangleListPrimitive` with the body surfaces |
//! | `box` | one `LINE_LIST` with the 12 edges of the box; a translucent `TriangleListPrimitive` per wall: its plane clipped to the box |
//!
//! A bond segment runs from particle `a` to `a + minimum_image(x_b − x_a)`,
//! and a surface face is drawn at its first corner's image, so nothing spans
//! the periodic box. Broken bonds (and bonds that never formed) are not
//! drawn. Bonds formed during the run by `bind` rules are not drawn either
//! (the scene draws the topology's bonds); `/cellmd/events` records them.
//! A wall whose plane misses the box is not drawn.

use foxglove::schemas::{
    line_primitive, Color, Duration, LinePrimitive, Point3, Pose, Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, Timestamp,
    TriangleListPrimitive, Vector3,
};
use glam::DVec3;
use serde_json::{json, Value};

use super::{FrameView, TopologyView, WallPlane};
use crate::system::SimBox;

/// Sphere radius drawn for types whose radius is 0 (length units).
pub const DEFAULT_RADIUS: f64 = 0.05;

/// Type colours (matplotlib's tab10), cycled by type index.
pub const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

const BOND_COLOR: [f64; 4] = [0.8, 0.8, 0.8, 1.0];
const SURFACE_COLOR: [f64; 4] = [0.95, 0.55, 0.35, 0.6];
const BOX_COLOR: [f64; 4] = [0.6, 0.6, 0.6, 1.0];
const WALL_COLOR: [f64; 4] = [0.55, 0.65, 0.8, 0.35];

macro_rules! fox_vector3 {
    () => {
        r#"{"title": "foxglove.Vector3", "type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}, "required": ["x", "y", "z"]}"#
    };
}
macro_rules! fox_point3 {
    () => {
        r#"{"title": "foxglove.Point3", "type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}, "required": ["x", "y", "z"]}"#
    };
}
macro_rules! fox_pose {
    () => {
        concat!(
            r#"{"title": "foxglove.Pose", "type": "object", "properties": {"position": "#,
            fox_vector3!(),
            r#", "orientation": {"title": "foxglove.Quaternion", "type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}}, "required": ["x", "y", "z", "w"]}}, "required": ["position", "orientation"]}"#
        )
    };
}
macro_rules! fox_color {
    () => {
        r#"{"title": "foxglove.Color", "type": "object", "properties": {"r": {"type": "number"}, "g": {"type": "number"}, "b": {"type": "number"}, "a": {"type": "number"}}, "required": ["r", "g", "b", "a"]}"#
    };
}
macro_rules! fox_time {
    () => {
        r#"{"type": "object", "title": "time", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}}"#
    };
}

/// JSON Schema of `foxglove.SceneUpdate`: the subset of Foxglove's published
/// schema that cellmd fills (primitive kinds it never writes are declared as
/// arrays and always empty).
pub const SCENE_UPDATE_SCHEMA: &str = concat!(
    r#"{"title": "foxglove.SceneUpdate", "description": "An update to the entities displayed in a 3D scene (subset used by cellmd)", "type": "object", "properties": {"#,
    r#""deletions": {"type": "array", "items": {"title": "foxglove.SceneEntityDeletion", "type": "object", "properties": {"timestamp": "#,
    fox_time!(),
    r#", "type": {"type": "integer", "description": "0 = MATCHING_ID, 1 = ALL"}, "id": {"type": "string"}}, "required": ["timestamp", "type", "id"]}}, "#,
    r#""entities": {"type": "array", "items": {"title": "foxglove.SceneEntity", "type": "object", "properties": {"#,
    r#""timestamp": "#,
    fox_time!(),
    r#", "frame_id": {"type": "string"}, "id": {"type": "string"}, "#,
    r#""lifetime": {"type": "object", "title": "duration", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}}, "#,
    r#""frame_locked": {"type": "boolean"}, "#,
    r#""metadata": {"type": "array", "items": {"title": "foxglove.KeyValuePair", "type": "object", "properties": {"key": {"type": "string"}, "value": {"type": "string"}}, "required": ["key", "value"]}}, "#,
    r#""arrows": {"type": "array", "description": "unused (always empty)"}, "#,
    r#""cubes": {"type": "array", "description": "unused (always empty)"}, "#,
    r#""spheres": {"type": "array", "items": {"title": "foxglove.SpherePrimitive", "type": "object", "properties": {"pose": "#,
    fox_pose!(),
    r#", "size": "#,
    fox_vector3!(),
    r#", "color": "#,
    fox_color!(),
    r#"}, "required": ["pose", "size", "color"]}}, "#,
    r#""cylinders": {"type": "array", "description": "unused (always empty)"}, "#,
    r#""lines": {"type": "array", "items": {"title": "foxglove.LinePrimitive", "type": "object", "properties": {"#,
    r#""type": {"title": "foxglove.LineType", "type": "integer", "description": "0 = LINE_STRIP, 1 = LINE_LOOP, 2 = LINE_LIST"}, "pose": "#,
    fox_pose!(),
    r#", "thickness": {"type": "number"}, "scale_invariant": {"type": "boolean"}, "points": {"type": "array", "items": "#,
    fox_point3!(),
    r#"}, "color": "#,
    fox_color!(),
    r#", "colors": {"type": "array", "items": "#,
    fox_color!(),
    r#"}, "indices": {"type": "array", "items": {"type": "integer", "minimum": 0}}}, "required": ["type", "pose", "thickness", "scale_invariant", "points", "color", "colors", "indices"]}}, "#,
    r#""triangles": {"type": "array", "items": {"title": "foxglove.TriangleListPrimitive", "type": "object", "properties": {"pose": "#,
    fox_pose!(),
    r#", "points": {"type": "array", "items": "#,
    fox_point3!(),
    r#"}, "color": "#,
    fox_color!(),
    r#", "colors": {"type": "array", "items": "#,
    fox_color!(),
    r#"}, "indices": {"type": "array", "items": {"type": "integer", "minimum": 0}}}, "required": ["pose", "points", "color", "colors", "indices"]}}, "#,
    r#""texts": {"type": "array", "description": "unused (always empty)"}, "#,
    r#""models": {"type": "array", "description": "unused (always empty)"}"#,
    r#"}, "required": ["timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"]}}"#,
    r#"}, "required": ["deletions", "entities"]}"#
);

/// What the scene needs of the topology, copied when the writer opens.
pub struct Scene {
    types: Vec<u32>,
    /// Drawn diameter per type.
    diameter: Vec<f64>,
    bonds: Vec<[u32; 2]>,
    triangles: Vec<[u32; 3]>,
}

impl Scene {
    pub fn new(topology: &TopologyView) -> Self {
        let diameter = (0..topology.type_names.len())
            .map(|t| 2.0 * topology.type_radius.get(t).copied().filter(|&r| r > 0.0).unwrap_or(DEFAULT_RADIUS))
            .collect();
        Self { types: topology.types.to_vec(), diameter, bonds: topology.bonds.to_vec(), triangles: topology.triangles.to_vec() }
    }

    /// The scene of `frame`, stamped `ns` nanoseconds.
    pub fn update(&self, frame: &FrameView, ns: u64) -> SceneUpdate {
        let b = frame.sim_box;
        let x = frame.positions;
        let spheres = x
            .iter()
            .zip(&self.types)
            .map(|(p, &t)| {
                let d = self.diameter[t as usize];
                SpherePrimitive { pose: Some(pose_at(*p)), size: Some(Vector3 { x: d, y: d, z: d }), color: Some(type_color(t as usize)) }
            })
            .collect();
        let mut bond_points = Vec::new();
        for (k, &[i, j]) in self.bonds.iter().enumerate() {
            if frame.is_bound(k) {
                let xa = x[i as usize];
                bond_points.extend([point(xa), point(xa + b.minimum_image(x[j as usize] - xa))]);
            }
        }
        let mut surface = Vec::with_capacity(3 * self.triangles.len());
        for &[i, j, k] in &self.triangles {
            let xa = x[i as usize];
            surface.push(point(xa));
            surface.extend([j, k].map(|p| point(xa + b.minimum_image(x[p as usize] - xa))));
        }
        let particles = SceneEntity {
            spheres,
            lines: non_empty(bond_points).map(|p| line_list(p, BOND_COLOR)).into_iter().collect(),
            triangles: non_empty(surface).map(|p| triangle_list(p, SURFACE_COLOR)).into_iter().collect(),
            ..entity("particles", ns)
        };
        let frame_box = SceneEntity {
            lines: vec![line_list(box_edges(b), BOX_COLOR)],
            triangles: frame.walls.iter().filter_map(|w| non_empty(wall_triangles(b, w))).map(|p| triangle_list(p, WALL_COLOR)).collect(),
            ..entity("box", ns)
        };
        SceneUpdate { deletions: Vec::new(), entities: vec![particles, frame_box] }
    }
}

fn non_empty<T>(v: Vec<T>) -> Option<Vec<T>> {
    (!v.is_empty()).then_some(v)
}

fn entity(id: &str, ns: u64) -> SceneEntity {
    let sec = u32::try_from(ns / 1_000_000_000).unwrap_or(u32::MAX);
    SceneEntity {
        timestamp: Some(Timestamp::new(sec, (ns % 1_000_000_000) as u32)),
        frame_id: "world".into(),
        id: id.into(),
        lifetime: Some(Duration::new(0, 0)),
        ..Default::default()
    }
}

fn point(p: DVec3) -> Point3 {
    Point3 { x: p.x, y: p.y, z: p.z }
}

fn pose_at(p: DVec3) -> Pose {
    Pose { position: Some(Vector3 { x: p.x, y: p.y, z: p.z }), orientation: Some(Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 }) }
}

fn color([r, g, b, a]: [f64; 4]) -> Color {
    Color { r, g, b, a }
}

fn type_color(t: usize) -> Color {
    let [r, g, b] = PALETTE[t % PALETTE.len()].map(|c| c as f64 / 255.0);
    Color { r, g, b, a: 1.0 }
}

fn line_list(points: Vec<Point3>, rgba: [f64; 4]) -> LinePrimitive {
    LinePrimitive {
        r#type: line_primitive::Type::LineList as i32,
        pose: Some(pose_at(DVec3::ZERO)),
        thickness: 2.0,
        scale_invariant: true,
        points,
        color: Some(color(rgba)),
        ..Default::default()
    }
}

fn triangle_list(points: Vec<Point3>, rgba: [f64; 4]) -> TriangleListPrimitive {
    TriangleListPrimitive { pose: Some(pose_at(DVec3::ZERO)), points, color: Some(color(rgba)), ..Default::default() }
}

/// The 8 corners of the box, corner `c` taking `hi` on axis `a` when bit `a` of `c` is set.
fn corners(b: &SimBox) -> [DVec3; 8] {
    std::array::from_fn(|c| DVec3::new([b.lo.x, b.hi.x][c & 1], [b.lo.y, b.hi.y][(c >> 1) & 1], [b.lo.z, b.hi.z][(c >> 2) & 1]))
}

/// The 12 edges of the box as corner pairs.
fn edges(b: &SimBox) -> impl Iterator<Item = (DVec3, DVec3)> {
    let c = corners(b);
    (0..8).flat_map(move |i| (0..3).filter(move |a| i & (1 << a) == 0).map(move |a| (c[i], c[i | (1 << a)])))
}

/// The box edges as `LINE_LIST` points.
fn box_edges(b: &SimBox) -> Vec<Point3> {
    edges(b).flat_map(|(p, q)| [point(p), point(q)]).collect()
}

/// The wall's plane clipped to the box, as a fan of triangles (empty when
/// the plane misses the box).
fn wall_triangles(b: &SimBox, w: &WallPlane) -> Vec<Point3> {
    let n = w.normal;
    let scale = b.lengths().max_element().max(f64::MIN_POSITIVE);
    let mut polygon: Vec<DVec3> = Vec::new();
    let mut add = |p: DVec3| {
        if polygon.iter().all(|q| (*q - p).length() > 1e-9 * scale) {
            polygon.push(p);
        }
    };
    for (p, q) in edges(b) {
        let (sp, sq) = (n.dot(p) - w.offset, n.dot(q) - w.offset);
        if sp == 0.0 {
            add(p);
        }
        if sq == 0.0 {
            add(q);
        }
        if sp * sq < 0.0 {
            add(p + (q - p) * (sp / (sp - sq)));
        }
    }
    if polygon.len() < 3 {
        return Vec::new();
    }
    let centre = polygon.iter().sum::<DVec3>() / polygon.len() as f64;
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let angle = |p: &DVec3| (*p - centre).dot(v).atan2((*p - centre).dot(u));
    polygon.sort_by(|p, q| angle(p).total_cmp(&angle(q)));
    (1..polygon.len() - 1).flat_map(|k| [polygon[0], polygon[k], polygon[k + 1]].map(point)).collect()
}

/// `update` as the JSON of [`SCENE_UPDATE_SCHEMA`] (every key present,
/// enums as integers, times as `{sec, nsec}`).
pub fn to_json(update: &SceneUpdate) -> Value {
    let vec3 = |v: &Option<Vector3>| v.as_ref().map_or(json!({"x": 0.0, "y": 0.0, "z": 0.0}), |v| json!({"x": v.x, "y": v.y, "z": v.z}));
    let points = |ps: &[Point3]| ps.iter().map(|p| json!({"x": p.x, "y": p.y, "z": p.z})).collect::<Vec<_>>();
    let rgba = |c: &Option<Color>| {
        c.as_ref().map_or(json!({"r": 0.0, "g": 0.0, "b": 0.0, "a": 0.0}), |c| json!({"r": c.r, "g": c.g, "b": c.b, "a": c.a}))
    };
    let pose = |p: &Option<Pose>| {
        let p = (*p).unwrap_or_default();
        let q = p.orientation.unwrap_or(Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 });
        json!({"position": vec3(&p.position), "orientation": {"x": q.x, "y": q.y, "z": q.z, "w": q.w}})
    };
    let entities: Vec<Value> = update
        .entities
        .iter()
        .map(|e| {
            let stamp = e.timestamp.unwrap_or_default();
            let lifetime = e.lifetime.unwrap_or_default();
            json!({
                "timestamp": {"sec": stamp.sec(), "nsec": stamp.nsec()},
                "frame_id": e.frame_id,
                "id": e.id,
                "lifetime": {"sec": lifetime.sec(), "nsec": lifetime.nsec()},
                "frame_locked": e.frame_locked,
                "metadata": [],
                "arrows": [],
                "cubes": [],
                "spheres": e.spheres.iter().map(|s| json!({"pose": pose(&s.pose), "size": vec3(&s.size), "color": rgba(&s.color)})).collect::<Vec<_>>(),
                "cylinders": [],
                "lines": e.lines.iter().map(|l| json!({
                    "type": l.r#type, "pose": pose(&l.pose), "thickness": l.thickness, "scale_invariant": l.scale_invariant,
                    "points": points(&l.points), "color": rgba(&l.color), "colors": [], "indices": []
                })).collect::<Vec<_>>(),
                "triangles": e.triangles.iter().map(|t| json!({
                    "pose": pose(&t.pose), "points": points(&t.points), "color": rgba(&t.color), "colors": [], "indices": []
                })).collect::<Vec<_>>(),
                "texts": [],
                "models": [],
            })
        })
        .collect();
    json!({"deletions": [], "entities": entities})
}

#[cfg(test)]
mod tests {
    use super::super::test_support::Sample;
    use super::*;

    /// Total area of a triangle list (three points per face).
    fn area(points: &[Point3]) -> f64 {
        let v = |p: &Point3| DVec3::new(p.x, p.y, p.z);
        points.chunks(3).map(|t| 0.5 * (v(&t[1]) - v(&t[0])).cross(v(&t[2]) - v(&t[0])).length()).sum()
    }

    #[test]
    fn only_bound_bonds_are_drawn() {
        let s = Sample::new(1);
        let scene = Scene::new(&s.topology());
        let mut frame = s.frame(0);
        let segments =
            |frame: &FrameView| -> Vec<Vec<Point3>> { scene.update(frame, 0).entities[0].lines.iter().map(|l| l.points.clone()).collect() };
        assert_eq!(segments(&frame)[0].len(), 4, "both bonds bound");
        frame.bound = &[false, true];
        let drawn = segments(&frame);
        assert_eq!(drawn[0].len(), 2);
        // Bond 1 joins particles 0 and 3, drawn to 3's nearest image (across the periodic y face).
        let (p0, p3) = (s.frames[0][0], s.frames[0][3]);
        let end = p0 + s.sim_box.minimum_image(p3 - p0);
        assert_eq!((drawn[0][1].x, drawn[0][1].y, drawn[0][1].z), (end.x, end.y, end.z));
        assert_eq!(end.y, -2.75);
        frame.bound = &[false, false];
        assert!(segments(&frame).is_empty(), "no line primitive without a bound bond");
    }

    #[test]
    fn walls_are_their_plane_clipped_to_the_box() {
        // The sample box is [0, 10] × [0, 10] × [−5, 5].
        let s = Sample::new(1);
        let scene = Scene::new(&s.topology());
        let diagonal = DVec3::new(1.0, 1.0, 0.0).normalize();
        let walls = [
            WallPlane { normal: DVec3::Z, offset: 0.0 },
            WallPlane { normal: DVec3::Z, offset: -5.0 },
            WallPlane { normal: diagonal, offset: 10.0 / 2f64.sqrt() },
            WallPlane { normal: -DVec3::X, offset: 3.0 },
        ];
        let mut frame = s.frame(0);
        frame.walls = &walls;
        let update = scene.update(&frame, 0);
        let frame_box = &update.entities[1];
        assert_eq!(frame_box.id, "box");
        assert_eq!(frame_box.lines[0].points.len(), 24);
        // The last wall (x = −3) misses the box and is not drawn.
        let areas: Vec<f64> = frame_box.triangles.iter().map(|t| area(&t.points)).collect();
        let want = [100.0, 100.0, 100.0 * 2f64.sqrt()];
        assert_eq!(areas.len(), want.len());
        for (a, w) in areas.iter().zip(want) {
            assert!((a - w).abs() < 1e-9 * w, "{areas:?}");
        }
        for (t, w) in frame_box.triangles.iter().zip(&walls) {
            for p in &t.points {
                assert!((w.normal.dot(DVec3::new(p.x, p.y, p.z)) - w.offset).abs() < 1e-12, "a corner off its plane");
            }
        }
    }

    #[test]
    fn json_carries_every_key_the_schema_requires() {
        let s = Sample::new(1);
        let walls = [WallPlane { normal: DVec3::Z, offset: 0.0 }];
        let mut frame = s.frame(0);
        frame.walls = &walls;
        let json = to_json(&Scene::new(&s.topology()).update(&frame, 1_500_000_000));
        let schema: Value = serde_json::from_str(SCENE_UPDATE_SCHEMA).unwrap();
        let required = |node: &Value| -> Vec<String> {
            node["required"].as_array().unwrap().iter().map(|k| k.as_str().unwrap().to_string()).collect()
        };
        let entity_schema = &schema["properties"]["entities"]["items"];
        for entity in json["entities"].as_array().unwrap() {
            for key in required(entity_schema) {
                assert!(entity.get(&key).is_some(), "entity lacks {key}");
            }
            for (kind, items) in
                [("lines", entity["lines"].clone()), ("triangles", entity["triangles"].clone()), ("spheres", entity["spheres"].clone())]
            {
                for item in items.as_array().unwrap() {
                    for key in required(&entity_schema["properties"][kind]["items"]) {
                        assert!(item.get(&key).is_some(), "{kind} lacks {key}");
                    }
                }
            }
        }
        assert_eq!(json["entities"][0]["timestamp"], json!({"sec": 1, "nsec": 500_000_000}));
        assert_eq!(json["entities"][1]["triangles"].as_array().unwrap().len(), 1);
        assert_eq!(json["entities"][0]["lines"][0]["type"], 2);
    }
}
