//! Triangle meshes for obstacles: reading Wavefront OBJ files and checking that a mesh bounds a
//! solid — closed, every edge shared by exactly two triangles that run it opposite ways,
//! outward-oriented (positive enclosed volume), without zero-area triangles. An obstacle's
//! inside is told from its outside only on such a mesh; anything else is rejected with the
//! first defect found.

use std::collections::HashMap;

/// Vertices and triangles of a mesh.
pub type MeshData = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// An OBJ file's mesh with, for each triangle, the file line of the face it came from.
#[derive(Clone, Debug, Default)]
pub struct ObjMesh {
    /// Vertices.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles (indices into `vertices`).
    pub triangles: Vec<[u32; 3]>,
    /// The 1-based line of each triangle's face.
    pub lines: Vec<usize>,
}

/// Reads a Wavefront OBJ file's `v` and `f` records (faces are triangulated as fans; texture and
/// normal indices are ignored).
pub fn read_obj(text: &str) -> Result<MeshData, String> {
    parse_obj(text).map(|m| (m.vertices, m.triangles))
}

/// [`read_obj`] keeping each triangle's line.
pub fn parse_obj(text: &str) -> Result<ObjMesh, String> {
    let mut m = ObjMesh::default();
    for (ln, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Result<Vec<f64>, _> = it.take(3).map(str::parse::<f64>).collect();
                match c {
                    Ok(c) if c.len() == 3 && c.iter().all(|v| v.is_finite()) => {
                        m.vertices.push([c[0], c[1], c[2]])
                    }
                    _ => return Err(format!("line {}: bad vertex", ln + 1)),
                }
            }
            Some("f") => {
                let n = m.vertices.len() as i64;
                let idx: Result<Vec<u32>, String> = it
                    .map(|tok| {
                        let i: i64 = tok
                            .split('/')
                            .next()
                            .unwrap_or("")
                            .parse()
                            .map_err(|_| format!("line {}: bad face index '{tok}'", ln + 1))?;
                        let k = if i < 0 { n + i } else { i - 1 };
                        if k < 0 || k >= n {
                            return Err(format!("line {}: face index {i} out of range", ln + 1));
                        }
                        Ok(k as u32)
                    })
                    .collect();
                let idx = idx?;
                if idx.len() < 3 {
                    return Err(format!("line {}: face with fewer than 3 vertices", ln + 1));
                }
                for k in 1..idx.len() - 1 {
                    m.triangles.push([idx[0], idx[k], idx[k + 1]]);
                    m.lines.push(ln + 1);
                }
            }
            _ => {}
        }
    }
    Ok(m)
}

/// What is wrong with a mesh; triangles are indices into the mesh's triangle list.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshDefect {
    /// No triangles.
    Empty,
    /// A vertex coordinate is not finite (after scaling).
    NotFinite { vertex: usize },
    /// The mesh is so large that its extent or volume overflows.
    TooLarge,
    /// A triangle with (numerically) zero area.
    Degenerate { triangle: usize },
    /// An edge belongs to one triangle only: the mesh has a hole.
    Open {
        triangle: usize,
        boundary_edges: usize,
    },
    /// An edge belongs to more than two triangles.
    NonManifold { triangle: usize },
    /// Two triangles sharing an edge run it the same way.
    Inconsistent { triangles: [usize; 2] },
    /// The enclosed volume is (numerically) zero.
    Flat,
    /// The triangles wind clockwise seen from outside: the mesh is inside-out.
    InsideOut { volume: f64 },
}

impl MeshDefect {
    /// The defect in words, with `line(t)` naming triangle `t` (e.g. by its file line).
    pub fn describe(&self, line: impl Fn(usize) -> String) -> String {
        match self {
            MeshDefect::Empty => "the mesh has no triangles".into(),
            MeshDefect::NotFinite { vertex } => {
                format!("vertex {} is not finite after scaling", vertex + 1)
            }
            MeshDefect::TooLarge => {
                "the mesh is too large after scaling (its volume overflows)".into()
            }
            MeshDefect::Degenerate { triangle } => {
                format!("the triangle of {} has zero area", line(*triangle))
            }
            MeshDefect::Open {
                triangle,
                boundary_edges,
            } => format!(
                "the mesh is not closed: {boundary_edges} edges belong to one triangle only \
                 (the first in the face of {})",
                line(*triangle)
            ),
            MeshDefect::NonManifold { triangle } => format!(
                "an edge of the face of {} belongs to more than two triangles",
                line(*triangle)
            ),
            MeshDefect::Inconsistent { triangles } => format!(
                "the faces of {} and {} share an edge but are wound the same way \
                 (not consistently oriented)",
                line(triangles[0]),
                line(triangles[1])
            ),
            MeshDefect::Flat => "the mesh encloses no volume (flat)".into(),
            MeshDefect::InsideOut { volume } => format!(
                "the mesh is inside-out (enclosed volume {volume:.3e} is negative): its faces \
                 must wind counter-clockwise seen from outside; reverse each face's vertices"
            ),
        }
    }
}

/// Checks that `vertices` and `triangles` bound a solid; returns its volume. Vertices at the
/// same position (as OBJ exporters write them per face) count as one.
pub fn check_solid(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<f64, MeshDefect> {
    if triangles.is_empty() {
        return Err(MeshDefect::Empty);
    }
    if let Some(v) = vertices
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(MeshDefect::NotFinite { vertex: v });
    }
    // One index per distinct position (positions compared exactly; -0 is 0).
    let mut first: HashMap<[u64; 3], u32> = HashMap::new();
    let id: Vec<u32> = vertices
        .iter()
        .enumerate()
        .map(|(i, p)| {
            *first
                .entry(p.map(|c| (c + 0.0).to_bits()))
                .or_insert(i as u32)
        })
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag2: f64 = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum();
    if !diag2.powf(1.5).is_finite() {
        return Err(MeshDefect::TooLarge);
    }
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let at = |i: u32| {
        let p = vertices[i as usize];
        [0, 1, 2].map(|k| p[k] - centre[k])
    };
    // Directed edges → the triangle that runs them.
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    let mut volume = 0.0;
    for (t, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| id[i as usize]);
        let (p, q, r) = (at(a), at(b), at(c));
        let u = [0, 1, 2].map(|k| q[k] - p[k]);
        let v = [0, 1, 2].map(|k| r[k] - p[k]);
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let area2 = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if a == b || b == c || a == c || area2.is_nan() || area2 <= 1e-12 * diag2 {
            return Err(MeshDefect::Degenerate { triangle: t });
        }
        volume += (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / 6.0;
        for e in [(a, b), (b, c), (c, a)] {
            if let Some(&other) = directed.get(&e) {
                return Err(if directed.contains_key(&(e.1, e.0)) {
                    MeshDefect::NonManifold { triangle: t }
                } else {
                    MeshDefect::Inconsistent {
                        triangles: [other, t],
                    }
                });
            }
            directed.insert(e, t);
        }
    }
    let mut boundary = directed
        .iter()
        .filter(|((a, b), _)| !directed.contains_key(&(*b, *a)))
        .map(|(_, &t)| t);
    if let Some(first_t) = boundary.clone().min() {
        return Err(MeshDefect::Open {
            triangle: first_t,
            boundary_edges: boundary.by_ref().count(),
        });
    }
    if volume.abs() <= 1e-9 * diag2.powf(1.5) {
        return Err(MeshDefect::Flat);
    }
    if volume < 0.0 {
        return Err(MeshDefect::InsideOut { volume });
    }
    Ok(volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube, outward (counter-clockwise seen from outside), 12 triangles.
    fn cube() -> MeshData {
        read_obj(include_str!("../../planning_cases/meshes/cube.obj")).unwrap()
    }

    #[test]
    fn the_shipped_cube_is_a_solid_of_its_volume() {
        let (v, t) = cube();
        let (lo, hi) = v
            .iter()
            .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
                (
                    [0, 1, 2].map(|k| lo[k].min(p[k])),
                    [0, 1, 2].map(|k| hi[k].max(p[k])),
                )
            });
        let box_volume: f64 = (0..3).map(|k| hi[k] - lo[k]).product();
        let vol = check_solid(&v, &t).unwrap();
        assert!(
            (vol - box_volume).abs() <= 1e-12 * box_volume,
            "{vol} vs {box_volume}"
        );
    }

    #[test]
    fn defects_are_found() {
        let (v, t) = cube();
        let mut open = t.clone();
        open.pop();
        assert!(matches!(
            check_solid(&v, &open),
            Err(MeshDefect::Open {
                boundary_edges: 3,
                ..
            })
        ));
        let flipped: Vec<[u32; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
        assert!(matches!(
            check_solid(&v, &flipped),
            Err(MeshDefect::InsideOut { .. })
        ));
        let mut one_flipped = t.clone();
        one_flipped[3] = [t[3][0], t[3][2], t[3][1]];
        assert!(matches!(
            check_solid(&v, &one_flipped),
            Err(MeshDefect::Inconsistent { .. })
        ));
        let mut doubled = t.clone();
        doubled.extend_from_slice(&t[..2]);
        assert!(check_solid(&v, &doubled).is_err());
        let flat: Vec<[f64; 3]> = v.iter().map(|p| [p[0], p[1], 0.0]).collect();
        assert!(check_solid(&flat, &t).is_err());
        let mut huge = v.clone();
        huge[0][0] = f64::INFINITY;
        assert_eq!(
            check_solid(&huge, &t),
            Err(MeshDefect::NotFinite { vertex: 0 })
        );
        assert_eq!(check_solid(&v, &[]), Err(MeshDefect::Empty));
        let big: Vec<[f64; 3]> = v.iter().map(|p| p.map(|c| c * 1e300)).collect();
        assert_eq!(check_solid(&big, &t), Err(MeshDefect::TooLarge));
        // A degenerate sliver: a triangle whose corners repeat.
        let mut sliver = t.clone();
        sliver.push([0, 0, 1]);
        assert!(matches!(
            check_solid(&v, &sliver),
            Err(MeshDefect::Degenerate { .. })
        ));
    }

    /// Per-face vertices (each triangle its own three copies, as exporters write them) are
    /// merged by position.
    #[test]
    fn duplicated_vertices_are_one() {
        let (v, t) = cube();
        let mut v2 = Vec::new();
        let mut t2 = Vec::new();
        for tri in &t {
            let base = v2.len() as u32;
            for &i in tri {
                v2.push(v[i as usize]);
            }
            t2.push([base, base + 1, base + 2]);
        }
        assert_eq!(check_solid(&v2, &t2), check_solid(&v, &t));
    }
}
