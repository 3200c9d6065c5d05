//! Silhouette chains: penumbra edges ([`penumbra_edges`](super::silhouette::penumbra_edges))
//! linked into polylines and simplified, so a finely tessellated caster's outline costs a few
//! long edges and few corners instead of thousands of sub-texel ones (issue 18: a 100k-triangle
//! koala's projected silhouette zigzags, 3 261 vertices for an outline about 1 500 smoothie
//! texels long).
//!
//! Edges are linked at vertices with exactly two of them; every other vertex (a loose end, a
//! fork of three or more, a vertex that does not project) ends a chain, and nothing merges across
//! it. Chains without ends are closed loops and stay closed. Each chain is then simplified by
//! Douglas–Peucker (Douglas & Peucker 1973), with the bound two-sided: every dropped vertex lies
//! within `tolerance` of its merged edge, and the width (penumbra size) interpolated along the
//! merged edge within `tolerance` of the vertex's own, so the merged polyline strays at most
//! `tolerance` from the original everywhere (both are connected between the same ends).
//!
//! Orientation: each chain is walked in one direction and its lit side found by a vote of its
//! edges' third vertices, each weighted by its distance from its edge's line. The lit
//! triangles' winding would give it directly, but penumbra edges carry the edge in the winding
//! of the adjacency's first face, whichever face is lit; the vote outweighs a near edge-on
//! triangle, whose third vertex can project to either side, where a single edge cannot.
//! Every output edge runs with the lit side on its left in the projection.

use glam::Vec2;

/// A penumbra edge: its two vertices and the third vertex of its light-facing triangle, as
/// [`penumbra_edges`](super::silhouette::penumbra_edges) gives them.
pub type PenumbraEdge = ([u32; 2], u32);

/// A vertex as the simplifier sees it: where it projects and its width there.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Point {
    p: Vec2,
    width: f32,
}

/// A merged edge: a penumbra edge for the run of original edges it replaces, with how far they
/// stray to either side of it, so that a consumer can cover the original on both sides (a quad
/// that starts on the merged edge leaves uncovered the sliver between it and an original edge
/// that bulges past it, lit where the original's penumbra began).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MergedEdge {
    /// Oriented lit side left, with the third vertex of one of the merged edges that lies left
    /// of it: a penumbra edge as consumers that find the outward side from the third vertex
    /// (smoothies, plateaus) take them.
    pub edge: PenumbraEdge,
    /// The farthest the original runs left of (inside) and right of (outside) this edge,
    /// at most the tolerance; 0 for an edge that merged nothing.
    pub inside: f32,
    pub outside: f32,
}

impl MergedEdge {
    /// An original edge, unmerged.
    pub fn single(edge: PenumbraEdge) -> Self {
        MergedEdge { edge, inside: 0.0, outside: 0.0 }
    }
}

/// The `edges` merged into fewer ones that stray at most `tolerance` from them in position and
/// in width, in the units of `project` and `width`, each oriented lit side left in `project`'s
/// plane (see [`MergedEdge`]). A run whose edges' own third vertices do not all lie left of them
/// (near edge-on triangles) stays unmerged, so its smoothies are what they were. Edges with an
/// end that does not project pass through unchanged. A `tolerance` of 0 (or less, or NaN) links
/// and orients the chains but merges nothing.
pub fn merge(
    edges: &[PenumbraEdge],
    project: impl Fn(u32) -> Option<Vec2>,
    width: impl Fn(u32) -> f32,
    tolerance: f32,
) -> Vec<MergedEdge> {
    let mut out = Vec::with_capacity(edges.len());
    let graph = Graph::new(edges, |v| project(v).map(|p| Point { p, width: width(v) }));
    let third = |e: usize| project(edges[e].1);
    for chain in graph.chains() {
        simplify(&graph, &chain, &third, tolerance, &mut out);
    }
    out.extend(graph.unprojected.iter().map(|&e| MergedEdge::single(edges[e])));
    out
}

/// The edges' incidence: for each edge end, the other edge at that vertex when the vertex has
/// exactly two (a chain runs through it), else none.
struct Graph<'a> {
    edges: &'a [PenumbraEdge],
    /// Per vertex number seen, sorted: the vertex and its point (`None`: does not project).
    points: Vec<(u32, Option<Point>)>,
    /// Per edge and end (2e + end): the next edge through that end's vertex, and which of its
    /// ends meets it, when the vertex joins exactly two edges.
    next: Vec<Option<(usize, usize)>>,
    /// Edges with an end that does not project.
    unprojected: Vec<usize>,
}

impl<'a> Graph<'a> {
    fn new(edges: &'a [PenumbraEdge], point: impl Fn(u32) -> Option<Point>) -> Self {
        // Every edge end by vertex; a vertex of two ends is a link.
        let mut ends: Vec<(u32, usize)> =
            edges.iter().enumerate().flat_map(|(e, (v, _))| [(v[0], 2 * e), (v[1], 2 * e + 1)]).collect();
        ends.sort_unstable();
        let mut next = vec![None; ends.len()];
        let mut points = Vec::new();
        for group in ends.chunk_by(|x, y| x.0 == y.0) {
            points.push((group[0].0, point(group[0].0)));
            // Two ends of one edge (a loop of one edge) link nothing.
            if let [(_, x), (_, y)] = *group
                && x / 2 != y / 2
            {
                next[x] = Some((y / 2, y % 2));
                next[y] = Some((x / 2, x % 2));
            }
        }
        let mut graph = Graph { edges, points, next, unprojected: Vec::new() };
        graph.unprojected = (0..edges.len()).filter(|&e| graph.ends(e).is_none()).collect();
        // Chains stop where an edge does not project.
        for &e in &graph.unprojected {
            for end in 0..2 {
                if let Some((f, g)) = graph.next[2 * e + end].take() {
                    graph.next[2 * f + g] = None;
                }
            }
        }
        graph
    }

    fn point(&self, v: u32) -> Option<Point> {
        let i = self.points.binary_search_by_key(&v, |(w, _)| *w).expect("a vertex of an edge");
        self.points[i].1
    }

    fn ends(&self, e: usize) -> Option<[Point; 2]> {
        let [a, b] = self.edges[e].0;
        Some([self.point(a)?, self.point(b)?])
    }

    /// Every chain of projected edges, each as (edge, whether it is walked b → a), in walking
    /// order: open chains from one end, then the closed loops.
    fn chains(&self) -> Vec<Vec<(usize, bool)>> {
        let mut seen = vec![false; self.edges.len()];
        for &e in &self.unprojected {
            seen[e] = true;
        }
        let mut chains = Vec::new();
        // Open chains start at an end with no link; loops anywhere.
        let starts = (0..self.edges.len())
            .flat_map(|e| [(e, 0), (e, 1)])
            .filter(|&(e, end)| self.next[2 * e + end].is_none())
            .chain((0..self.edges.len()).map(|e| (e, 0)));
        for (e, end) in starts {
            if seen[e] {
                continue;
            }
            // Walk in from `end`: the edge runs away from it.
            let mut chain = Vec::new();
            let (mut e, mut from) = (e, end);
            while !seen[e] {
                seen[e] = true;
                chain.push((e, from == 1));
                match self.next[2 * e + (1 - from)] {
                    Some((f, at)) => (e, from) = (f, at),
                    None => break,
                }
            }
            chains.push(chain);
        }
        chains
    }
}

/// One chain simplified into `out`, oriented lit side left.
fn simplify(
    graph: &Graph<'_>,
    chain: &[(usize, bool)],
    third: &impl Fn(usize) -> Option<Vec2>,
    tolerance: f32,
    out: &mut Vec<MergedEdge>,
) {
    // The chain's vertices in walking order (n + 1 of them; a loop repeats its first).
    let vertex = |&(e, reversed): &(usize, bool)| graph.edges[e].0[reversed as usize];
    let mut vertices: Vec<u32> = chain.iter().map(vertex).collect();
    let (last, reversed) = chain[chain.len() - 1];
    vertices.push(graph.edges[last].0[1 - reversed as usize]);
    let mut points: Vec<Point> = vertices.iter().map(|&v| graph.point(v).expect("projected chains")).collect();
    // The vote: each third vertex's signed distance from its edge's line, lit side left.
    let vote: f32 =
        chain.iter().enumerate().filter_map(|(i, &(e, _))| Some(side(points[i].p, points[i + 1].p, third(e)?))).sum();
    let mut edges: Vec<usize> = chain.iter().map(|&(e, _)| e).collect();
    if vote < 0.0 {
        vertices.reverse();
        points.reverse();
        edges.reverse();
    }
    // Runs [i, j] of vertices; a run becomes one edge when it keeps the bound.
    let merging = tolerance > 0.0;
    let accepts = |i: usize, j: usize| -> Result<MergedEdge, usize> {
        let edge = [vertices[i], vertices[j]];
        if j == i + 1 {
            return Ok(MergedEdge::single((edge, graph.edges[edges[i]].1)));
        }
        if !merging {
            return Err((i + j) / 2);
        }
        let (a, b) = (points[i], points[j]);
        let chord = b.p - a.p;
        let length2 = chord.length_squared();
        let mut worst = (0.0f32, (i + j) / 2);
        for (k, q) in points.iter().enumerate().take(j).skip(i + 1) {
            let s = if length2 > 0.0 { ((q.p - a.p).dot(chord) / length2).clamp(0.0, 1.0) } else { 0.0 };
            let off = (q.p - (a.p + chord * s)).length().max((q.width - (a.width + (b.width - a.width) * s)).abs());
            if off > worst.0 {
                worst = (off, k);
            }
        }
        // Not a bound that holds (NaN included) or a chord with no direction: split.
        let holds = worst.0 <= tolerance && length2 > 0.0;
        if !holds {
            return Err(worst.1);
        }
        // The representative third vertex: the farthest left of the merged edge.
        if (i..j).any(|k| third(edges[k]).is_none_or(|c| side(points[k].p, points[k + 1].p, c) <= 0.0)) {
            return Err(worst.1);
        }
        let best = (i..j)
            .filter_map(|k| Some((side(a.p, b.p, third(edges[k])?), graph.edges[edges[k]].1)))
            .max_by(|x, y| x.0.total_cmp(&y.0));
        let Some((_, c)) = best.filter(|(d, _)| *d > 0.0) else { return Err(worst.1) };
        // How far the dropped vertices (and so the edges between them) lie to either side.
        let sides = (i + 1..j).map(|k| side(a.p, b.p, points[k].p));
        let (inside, outside) = sides.fold((0.0f32, 0.0f32), |(l, r), d| (l.max(d), r.max(-d)));
        Ok(MergedEdge { edge: (edge, c), inside, outside })
    };
    let mut runs = vec![(0, vertices.len() - 1)];
    if vertices[0] == vertices[vertices.len() - 1] && vertices.len() > 2 {
        // A loop: split at the vertex farthest from its start, so no run's chord is empty.
        let far = (1..vertices.len() - 1)
            .max_by(|&x, &y| (points[x].p - points[0].p).length().total_cmp(&(points[y].p - points[0].p).length()))
            .expect("three vertices or more");
        runs = vec![(far, vertices.len() - 1), (0, far)];
    }
    while let Some((i, j)) = runs.pop() {
        match accepts(i, j) {
            Ok(merged) => out.push(merged),
            Err(k) => runs.extend([(k, j), (i, k)]),
        }
    }
}

/// How far `c` lies left of the line a → b (negative: right; 0 where a = b).
fn side(a: Vec2, b: Vec2, c: Vec2) -> f32 {
    let d = b - a;
    let length = d.length();
    if length > 0.0 { d.perp_dot(c - a) / length } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// What a chain's vertices project to and their widths, by vertex number.
    struct Outline {
        points: Vec<Vec2>,
        widths: Vec<f32>,
    }

    impl Outline {
        fn merged(&self, edges: &[PenumbraEdge], tolerance: f32) -> Vec<MergedEdge> {
            let points = &self.points;
            merge(edges, |v| points.get(v as usize).copied(), |v| self.widths[v as usize], tolerance)
        }

        fn merge(&self, edges: &[PenumbraEdge], tolerance: f32) -> Vec<PenumbraEdge> {
            self.merged(edges, tolerance).iter().map(|m| m.edge).collect()
        }
    }

    /// A wobbly closed outline of `n` vertices around the origin (radius 1 ± `wobble`), wound
    /// counter-clockwise, with the lit inside marked by a third vertex at the centre (number
    /// n), and its edges in a shuffled order, some reversed.
    fn wobbly(n: usize, wobble: &[f32], order: &[usize]) -> (Outline, Vec<PenumbraEdge>) {
        let mut points: Vec<Vec2> = (0..n)
            .map(|i| {
                let angle = i as f32 / n as f32 * std::f32::consts::TAU;
                Vec2::from_angle(angle) * (1.0 + wobble[i % wobble.len()])
            })
            .collect();
        points.push(Vec2::ZERO);
        let widths = (0..=n).map(|i| 0.05 + 0.01 * wobble[i % wobble.len()]).collect();
        let mut edges: Vec<PenumbraEdge> = (0..n as u32).map(|i| ([i, (i + 1) % n as u32], n as u32)).collect();
        for (k, &o) in order.iter().enumerate() {
            let (a, b) = (k % n, o % n);
            edges.swap(a, b);
            if o % 3 == 0 {
                edges[a].0.reverse();
            }
        }
        (Outline { points, widths }, edges)
    }

    /// Distance from `q` to the segment a–b.
    fn to_segment(q: Vec2, a: Vec2, b: Vec2) -> f32 {
        let d = b - a;
        let s = if d.length_squared() > 0.0 { ((q - a).dot(d) / d.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
        (q - (a + d * s)).length()
    }

    /// The merged edges form one closed loop over the original's vertices, in order.
    fn loop_of(merged: &[PenumbraEdge]) -> Vec<u32> {
        let start = merged[0].0[0];
        let mut loop_ = vec![start];
        let mut at = start;
        for _ in 0..merged.len() {
            let next = merged.iter().find(|e| e.0[0] == at).expect("head to tail");
            at = next.0[1];
            loop_.push(at);
        }
        loop_
    }

    proptest! {
        #[test]
        fn a_closed_outline_merges_into_a_closed_loop_within_the_bound(
            n in 3usize..200,
            wobble in prop::collection::vec(-0.02f32..0.02, 1..9),
            order in prop::collection::vec(0usize..1000, 0..50),
            tolerance in 0.0f32..0.1,
        ) {
            let (outline, edges) = wobbly(n, &wobble, &order);
            let sides = outline.merged(&edges, tolerance);
            let merged: Vec<PenumbraEdge> = sides.iter().map(|m| m.edge).collect();
            prop_assert!(!merged.is_empty() && merged.len() <= edges.len());
            // Closed: every vertex starts one merged edge and ends one, and they make one loop.
            let loop_ = loop_of(&merged);
            prop_assert_eq!(loop_.first(), loop_.last(), "the loop closes");
            let mut starts: Vec<u32> = merged.iter().map(|e| e.0[0]).collect();
            starts.sort_unstable();
            starts.dedup();
            prop_assert_eq!(starts.len(), merged.len(), "each vertex starts at most one edge");
            // Counter-clockwise like the outline (lit inside on the left), dropped vertices in
            // order between their edge's ends and within the bound, in position and in width.
            let p = |v: u32| outline.points[v as usize];
            for (e, m) in merged.iter().zip(&sides) {
                prop_assert!(m.inside >= 0.0 && m.outside >= 0.0 && m.inside.max(m.outside) <= tolerance * 1.0001 + 1e-6);
                let (a, b) = (e.0[0] as usize, e.0[1] as usize);
                prop_assert!((p(e.0[1]) - p(e.0[0])).perp_dot(p(e.1) - p(e.0[0])) > 0.0, "lit side left: {e:?}");
                let dropped: Vec<usize> = if a < b { (a + 1..b).collect() } else { (a + 1..n).chain(0..b).collect() };
                let (pa, pb) = (p(e.0[0]), p(e.0[1]));
                for k in dropped {
                    let q = outline.points[k];
                    prop_assert!(to_segment(q, pa, pb) <= tolerance * 1.0001 + 1e-6, "vertex {k} strays from {e:?}");
                    let left = (pb - pa).perp_dot(q - pa) / (pb - pa).length();
                    prop_assert!(left <= m.inside + 1e-6 && -left <= m.outside + 1e-6, "{k} beyond {m:?}");
                    let d = pb - pa;
                    let s = ((q - pa).dot(d) / d.length_squared()).clamp(0.0, 1.0);
                    let w = outline.widths[a] + (outline.widths[b] - outline.widths[a]) * s;
                    prop_assert!((outline.widths[k] - w).abs() <= tolerance * 1.0001 + 1e-6, "width at {k}");
                }
            }
            if tolerance == 0.0 {
                prop_assert_eq!(merged.len(), edges.len(), "nothing merges at 0");
            }
        }

        #[test]
        fn nothing_merges_across_a_fork_or_a_loose_end(
            n in 4usize..60,
            fork in 0usize..60,
            tolerance in 0.01f32..1.0,
        ) {
            // A straight open chain 0 – 1 – … – n−1 along x, lit side up, and a spur at `fork`:
            // a third edge there. Ends and the fork are kept; between them everything merges.
            let fork = 1 + fork % (n - 2);
            let mut points: Vec<Vec2> = (0..n).map(|i| Vec2::new(i as f32, 0.0)).collect();
            points.extend([Vec2::new(0.0, 5.0), Vec2::new(fork as f32, -1.0)]);
            let widths = vec![0.1; n + 2];
            let outline = Outline { points, widths };
            let lit = n as u32;
            let mut edges: Vec<PenumbraEdge> = (0..n as u32 - 1).map(|i| ([i + 1, i], lit)).collect();
            edges.push(([fork as u32, n as u32 + 1], lit));
            let merged = outline.merge(&edges, tolerance);
            // The straight chain's merged edges (not the spur) end at the ends and the fork.
            let chain = merged.iter().filter(|e| !e.0.contains(&(n as u32 + 1)));
            let mut kept: Vec<u32> = chain.flat_map(|e| e.0).collect();
            kept.sort_unstable();
            kept.dedup();
            let mut expected = vec![0, fork as u32, n as u32 - 1];
            expected.dedup();
            prop_assert_eq!(kept, expected);
            for e in &merged {
                prop_assert!(e.0[0] < e.0[1] || e.0.contains(&(n as u32 + 1)), "walked left to right, lit side left");
            }
        }
    }

    #[test]
    fn a_zigzag_merges_to_its_chord_and_breaks_where_it_strays() {
        // A zigzag of amplitude 0.1 along x, lit above (third vertex far up).
        let n = 21;
        let mut points: Vec<Vec2> = (0..n).map(|i| Vec2::new(i as f32, if i % 2 == 1 { 0.1 } else { 0.0 })).collect();
        points.push(Vec2::new(10.0, 100.0));
        let outline = Outline { points, widths: vec![1.0; n + 1] };
        let edges: Vec<PenumbraEdge> = (0..n as u32 - 1).map(|i| ([i, i + 1], n as u32)).collect();
        assert_eq!(outline.merge(&edges, 0.2), [([0, 20], n as u32)], "one edge, walked lit side left");
        let [m] = outline.merged(&edges, 0.2)[..] else { panic!("one edge") };
        assert!((m.inside - 0.1).abs() < 1e-6 && m.outside == 0.0, "the peaks lie inside: {m:?}");
        assert_eq!(outline.merge(&edges, 0.05).len(), edges.len(), "under the amplitude: nothing merges");
        // A width that jumps at the middle stops the merge there.
        let mut widths = vec![1.0; n + 1];
        widths[10] = 2.0;
        let outline = Outline { widths, ..outline };
        assert!(outline.merge(&edges, 0.2).iter().any(|e| e.0.contains(&10)));
    }

    #[test]
    fn edges_that_do_not_project_pass_through_and_end_chains() {
        // 0 – 1 – 2 – 3 straight, lit above, vertex 2 behind the light.
        let points = [Vec2::ZERO, Vec2::X, Vec2::new(2.0, 0.0), Vec2::new(3.0, 0.0), Vec2::new(1.0, 1.0)];
        let edges: Vec<PenumbraEdge> = (0..3).map(|i| ([i, i + 1], 4)).collect();
        let merged = merge(&edges, |v| (v != 2).then(|| points[v as usize]), |_| 0.1, 1.0);
        let mut sorted: Vec<PenumbraEdge> = merged.iter().map(|m| m.edge).collect();
        sorted.sort_unstable();
        assert_eq!(sorted, [([0, 1], 4), ([1, 2], 4), ([2, 3], 4)]);
    }

    #[test]
    fn the_side_vote_outweighs_an_edge_on_triangle() {
        // A straight chain lit above, one edge's third vertex just below its line (a near
        // edge-on triangle): the chain still turns lit side left; that edge stays as it was
        // (its smoothie unchanged), the runs on either side merge.
        let mut points: Vec<Vec2> = (0..6).map(|i| Vec2::new(i as f32, 0.0)).collect();
        points.extend([Vec2::new(2.5, 1.0), Vec2::new(2.5, -1e-4)]);
        let outline = Outline { points, widths: vec![0.1; 8] };
        let edges: Vec<PenumbraEdge> = (0..5).map(|i| ([i + 1, i], if i == 2 { 7 } else { 6 })).collect();
        assert_eq!(outline.merge(&edges, 0.01), [([0, 2], 6), ([2, 3], 7), ([3, 5], 6)]);
    }
}
