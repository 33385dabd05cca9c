//! Validation of `[ bodies ]` and `[ triangles ]`: every body must be a
//! closed, consistently oriented 2-manifold of sphere topology.
//!
//! Checked per body, faces in file order, the first violation reported at
//! the offending face's line:
//!
//! 1. **Orientation**: no directed edge a→b is used by two faces (outward
//!    winding makes two neighbouring faces traverse their shared edge in
//!    opposite directions). This also rules out an edge in three or more
//!    faces, and a face listed twice.
//! 2. **Closed**: every directed edge a→b has its reverse b→a in another
//!    face of the body (no hole, no boundary).
//! 3. **Manifold vertices**: the faces around each vertex form one fan
//!    (two cones touching at a tip are refused).
//! 4. **Connected**: every face is reachable from the first through shared
//!    edges (a body is one surface).
//! 5. **Sphere topology**: Euler characteristic V − E + F = 2.
//!
//! Also: a body has at least one face, and a particle whose `[ particles ]`
//! record names a body is used only by that body's faces.

use std::collections::HashMap;

use super::types::Topology;
use crate::input::{InputError, Token};

fn face_text(top: &Topology, face: [u32; 3]) -> String {
    let ids = face.map(|p| top.ids[p as usize]);
    format!("({}, {}, {})", ids[0], ids[1], ids[2])
}

/// Checks every body of a parsed topology; `face_tokens[t]` is the first token
/// of triangle `t`'s line and `body_tokens[b]` the id token of body `b`.
pub(super) fn check_bodies(top: &Topology, face_tokens: &[Token], body_tokens: &[Token]) -> Result<(), InputError> {
    let by_body = top.faces_by_body();
    for (b, (body, _)) in top.bodies.iter().enumerate() {
        let faces = by_body.get(body).map_or(&[][..], Vec::as_slice);
        if faces.is_empty() {
            return Err(body_tokens[b]
                .error(format!("body {body} has no faces, expected a closed surface: its triangles in [ triangles ] as `{body} i j k`")));
        }
        check_body(top, *body, faces, face_tokens)?;
    }
    Ok(())
}

fn check_body(top: &Topology, body: u64, faces: &[usize], tokens: &[Token]) -> Result<(), InputError> {
    let tri = |t: usize| top.triangles[t].1;
    let id = |p: u32| top.ids[p as usize];
    // Particles that name another body.
    for &t in faces {
        for p in tri(t) {
            if let Some(other) = top.body_of[p as usize].filter(|&other| other != body) {
                return Err(tokens[t].error(format!(
                    "face {} of body {body} uses particle {}, which [ particles ] puts in body {other}; expected the particles of a body's own faces",
                    face_text(top, tri(t)),
                    id(p)
                )));
            }
        }
    }
    // 1. Each directed edge at most once.
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for &t in faces {
        let [a, b, c] = tri(t);
        for (u, v) in [(a, b), (b, c), (c, a)] {
            if let Some(&first) = directed.get(&(u, v)) {
                return Err(tokens[t].error(format!(
                    "face {} of body {body} traverses edge {}→{} in the same direction as the face at line {}; expected consistently oriented (outward-wound) faces, each edge once in each direction",
                    face_text(top, tri(t)),
                    id(u),
                    id(v),
                    tokens[first].line
                )));
            }
            directed.insert((u, v), t);
        }
    }
    // 2. Closed: every directed edge has its reverse.
    for &t in faces {
        let [a, b, c] = tri(t);
        for (u, v) in [(a, b), (b, c), (c, a)] {
            if !directed.contains_key(&(v, u)) {
                return Err(tokens[t].error(format!(
                    "edge {}–{} of face {} belongs to no other face of body {body}; expected a closed surface, every edge shared by exactly two faces",
                    id(u),
                    id(v),
                    face_text(top, tri(t))
                )));
            }
        }
    }
    // 3. One fan around each vertex: walk from a face around its vertex v
    //    (face (v, a, b) → the face holding v→b) and count the faces met.
    let mut incident: HashMap<u32, Vec<usize>> = HashMap::new();
    for &t in faces {
        for p in tri(t) {
            incident.entry(p).or_default().push(t);
        }
    }
    let rotated = |t: usize, v: u32| {
        let f = tri(t);
        let k = f.iter().position(|&p| p == v).expect("v is a corner of t");
        [f[k], f[(k + 1) % 3], f[(k + 2) % 3]]
    };
    let mut vertices: Vec<u32> = incident.keys().copied().collect();
    vertices.sort_unstable();
    for &v in &vertices {
        let around = &incident[&v];
        let start = around[0];
        let mut fan = vec![start];
        let mut t = start;
        loop {
            let [_, _, b] = rotated(t, v);
            t = directed[&(v, b)];
            if t == start {
                break;
            }
            fan.push(t);
        }
        if fan.len() < around.len() {
            let stray = *around.iter().find(|t| !fan.contains(t)).expect("a face outside the fan");
            return Err(tokens[stray].error(format!(
                "face {} of body {body} touches the other faces around particle {} only at that vertex (one fan of {} faces around it, {} faces outside that fan); expected a 2-manifold: one fan of faces around each vertex",
                face_text(top, tri(stray)),
                id(v),
                fan.len(),
                around.len() - fan.len()
            )));
        }
    }
    // 4. Connected through shared edges.
    let mut reached = vec![false; faces.len()];
    let local: HashMap<usize, usize> = faces.iter().enumerate().map(|(k, &t)| (t, k)).collect();
    let mut stack = vec![0usize];
    reached[0] = true;
    while let Some(k) = stack.pop() {
        let [a, b, c] = tri(faces[k]);
        for (u, v) in [(a, b), (b, c), (c, a)] {
            let n = local[&directed[&(v, u)]];
            if !reached[n] {
                reached[n] = true;
                stack.push(n);
            }
        }
    }
    if let Some(k) = reached.iter().position(|r| !r) {
        let t = faces[k];
        return Err(tokens[t].error(format!(
            "face {} of body {body} is not connected to the body's first face (line {}) through shared edges; expected one connected surface per body",
            face_text(top, tri(t)),
            tokens[faces[0]].line
        )));
    }
    // 5. Euler characteristic.
    let (v, e, f) = (vertices.len() as i64, directed.len() as i64 / 2, faces.len() as i64);
    let chi = v - e + f;
    if chi != 2 {
        return Err(tokens[faces[0]].error(format!(
            "body {body} (first face {} here) has Euler characteristic V − E + F = {v} − {e} + {f} = {chi}, expected 2: a closed surface of sphere topology",
            face_text(top, tri(faces[0]))
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::input::SourceFile;
    use crate::topology::parse_topology;

    /// A tetrahedron (outward-wound) of body 1, with extra lines appended.
    fn tetrahedron(faces: &str) -> String {
        format!("[ particles ]\n1 a 0 0 0\n2 a 1 0 0\n3 a 0 1 0\n4 a 0 0 1\n5 a 1 1 1\n6 a 2 1 1\n7 a 1 2 1\n8 a 1 1 2\n[ bodies ]\n1 cell\n[ triangles ]\n{faces}")
    }

    const GOOD: &str = "1 1 3 2\n1 1 2 4\n1 2 3 4\n1 3 1 4\n";

    fn parse(text: &str) -> Result<(), String> {
        parse_topology(&SourceFile::new("t.top", text)).map(|_| ()).map_err(|e| e.to_string())
    }

    #[test]
    fn a_closed_oriented_tetrahedron_passes() {
        parse(&tetrahedron(GOOD)).unwrap();
        // Two bodies, the second a translated copy.
        let two = tetrahedron(GOOD).replace("[ triangles ]", "2 nucleus\n[ triangles ]") + "2 5 7 6\n2 5 6 8\n2 6 7 8\n2 7 5 8\n";
        parse(&two).unwrap();
    }

    #[test]
    fn violations_name_the_face() {
        // One face wound the wrong way.
        assert_eq!(
            parse(&tetrahedron("1 1 3 2\n1 1 2 4\n1 2 4 3\n1 3 1 4\n")).unwrap_err(),
            "t.top:15:1: face (2, 4, 3) of body 1 traverses edge 2→4 in the same direction as the face at line 14; expected consistently oriented (outward-wound) faces, each edge once in each direction"
        );
        // A missing face: a hole.
        assert_eq!(
            parse(&tetrahedron("1 1 3 2\n1 1 2 4\n1 2 3 4\n")).unwrap_err(),
            "t.top:13:1: edge 1–3 of face (1, 3, 2) belongs to no other face of body 1; expected a closed surface, every edge shared by exactly two faces"
        );
        // Two tetrahedra sharing vertex 1 in one body: a pinched vertex.
        let pinched = tetrahedron(&format!("{GOOD}1 1 6 5\n1 1 5 7\n1 5 6 7\n1 6 1 7\n"));
        assert!(parse(&pinched)
            .unwrap_err()
            .starts_with("t.top:17:1: face (1, 6, 5) of body 1 touches the other faces around particle 1 only at that vertex"));
        // Two separate tetrahedra in one body.
        let split = tetrahedron(&format!("{GOOD}1 5 7 6\n1 5 6 8\n1 6 7 8\n1 7 5 8\n"));
        assert!(parse(&split)
            .unwrap_err()
            .starts_with("t.top:17:1: face (5, 7, 6) of body 1 is not connected to the body's first face (line 13)"));
        // A body without faces.
        assert_eq!(
            parse(&tetrahedron(GOOD).replace("[ triangles ]", "2 empty\n[ triangles ]")).unwrap_err(),
            "t.top:12:1: body 2 has no faces, expected a closed surface: its triangles in [ triangles ] as `2 i j k`"
        );
        // A particle that names another body.
        let claimed = tetrahedron(GOOD).replace("4 a 0 0 1\n", "4 a 0 0 1 2\n").replace("[ triangles ]", "2 other\n[ triangles ]")
            + "2 5 7 6\n2 5 6 8\n2 6 7 8\n2 7 5 8\n";
        assert_eq!(
            parse(&claimed).unwrap_err(),
            "t.top:15:1: face (1, 2, 4) of body 1 uses particle 4, which [ particles ] puts in body 2; expected the particles of a body's own faces"
        );
    }

    #[test]
    fn a_torus_fails_the_euler_characteristic() {
        // 3×3 grid torus: 9 vertices, 27 edges, 18 faces, χ = 0.
        let mut text = String::from("[ particles ]\n");
        for k in 0..9 {
            text += &format!("{} a {} {} 0\n", k + 1, k % 3, k / 3);
        }
        text += "[ bodies ]\n7 ring\n[ triangles ]\n";
        let v = |i: usize, j: usize| (i % 3) + 3 * (j % 3) + 1;
        for i in 0..3 {
            for j in 0..3 {
                text += &format!("7 {} {} {}\n", v(i, j), v(i + 1, j), v(i + 1, j + 1));
                text += &format!("7 {} {} {}\n", v(i, j), v(i + 1, j + 1), v(i, j + 1));
            }
        }
        assert_eq!(
            parse(&text).unwrap_err(),
            "t.top:14:1: body 7 (first face (1, 2, 5) here) has Euler characteristic V − E + F = 9 − 27 + 18 = 0, expected 2: a closed surface of sphere topology"
        );
    }
}
