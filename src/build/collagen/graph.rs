//! The network graph of `cellmd build collagen` before it is written:
//! nodes with positions and kinds, fibre edges and bending angles.

use std::collections::VecDeque;

use glam::DVec2;

/// What one end of a piece of fibre is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum End {
    /// A free end inside the network: trimmed back to the last crosslink.
    Free,
    /// Cut at the rectangle's edge: an anchor node.
    Edge,
    /// At the circle of cell `c`: attached to its nearest ring node.
    Cell(usize),
}

/// A node of the network graph before it is written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Kind {
    Ring,
    Node,
    Anchor,
}

/// The network graph: nodes with positions and kinds, edges between them.
#[derive(Default)]
pub(super) struct Graph {
    pub(super) nodes: Vec<(DVec2, Kind)>,
    pub(super) edges: Vec<[usize; 2]>,
    /// Bending angles (vertex in the middle) where a fibre runs straight.
    pub(super) angles: Vec<[usize; 3]>,
    /// The edges (i < j, MAX) and angles (ends i < k, vertex) listed so far.
    pub(super) listed: std::collections::HashSet<(usize, usize, usize)>,
}

impl Graph {
    pub(super) fn node(&mut self, x: DVec2, kind: Kind) -> usize {
        self.nodes.push((x, kind));
        self.nodes.len() - 1
    }

    /// Joins consecutive nodes of `chain` (one piece of a fibre) by the
    /// fewest equal bonds no longer than `ell` each, and adds an angle at
    /// every node between two bonds that continue in a straight line.
    pub(super) fn fibre(&mut self, chain: &[usize], ell: f64) {
        let mut path = vec![chain[0]];
        for pair in chain.windows(2) {
            let (pa, pb) = (self.nodes[pair[0]].0, self.nodes[pair[1]].0);
            let m = ((pb - pa).length() / ell).ceil().max(1.0) as usize;
            for s in 1..m {
                path.push(self.node(pa.lerp(pb, s as f64 / m as f64), Kind::Node));
            }
            path.push(pair[1]);
        }
        // Two fibres through the same merged crosslinks share those bonds and angles: listed once.
        for pair in path.windows(2) {
            if self.listed.insert((pair[0].min(pair[1]), pair[0].max(pair[1]), usize::MAX)) {
                self.edges.push([pair[0], pair[1]]);
            }
        }
        for t in path.windows(3) {
            let (u, v) = (self.nodes[t[1]].0 - self.nodes[t[0]].0, self.nodes[t[2]].0 - self.nodes[t[1]].0);
            let straight = u.dot(v) > 0.0 && u.perp_dot(v).abs() <= 1e-12 * u.length() * v.length();
            if straight && self.listed.insert((t[0].min(t[2]), t[0].max(t[2]), t[1])) {
                self.angles.push([t[0], t[1], t[2]]);
            }
        }
    }

    /// Which nodes and edges stay: network nodes left with one bond go
    /// (repeatedly), then every piece that reaches no anchor and no ring node.
    pub(super) fn prune(&self) -> (Vec<bool>, Vec<bool>) {
        let n = self.nodes.len();
        let mut adjacent: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (e, &[a, b]) in self.edges.iter().enumerate() {
            adjacent[a].push(e);
            adjacent[b].push(e);
        }
        let mut edge_alive = vec![true; self.edges.len()];
        let mut degree: Vec<usize> = adjacent.iter().map(Vec::len).collect();
        let mut node_alive = vec![true; n];
        let free = |k: usize| self.nodes[k].1 == Kind::Node;
        let mut queue: VecDeque<usize> = (0..n).filter(|&k| free(k) && degree[k] <= 1).collect();
        while let Some(k) = queue.pop_front() {
            if !node_alive[k] {
                continue;
            }
            node_alive[k] = false;
            for &e in &adjacent[k] {
                if edge_alive[e] {
                    edge_alive[e] = false;
                    let other = if self.edges[e][0] == k { self.edges[e][1] } else { self.edges[e][0] };
                    degree[other] -= 1;
                    if free(other) && degree[other] <= 1 {
                        queue.push_back(other);
                    }
                }
            }
        }
        // Keep what an anchor or a ring node reaches.
        let mut reached = vec![false; n];
        let mut queue: VecDeque<usize> = (0..n).filter(|&k| node_alive[k] && !free(k)).collect();
        for &k in &queue {
            reached[k] = true;
        }
        while let Some(k) = queue.pop_front() {
            for &e in &adjacent[k] {
                let other = if self.edges[e][0] == k { self.edges[e][1] } else { self.edges[e][0] };
                if edge_alive[e] && !reached[other] {
                    reached[other] = true;
                    queue.push_back(other);
                }
            }
        }
        let keep: Vec<bool> = (0..n).map(|k| node_alive[k] && (reached[k] || self.nodes[k].1 == Kind::Ring)).collect();
        let edges = self.edges.iter().zip(&edge_alive).map(|(&[a, b], &alive)| alive && keep[a] && keep[b]).collect();
        (keep, edges)
    }
}
