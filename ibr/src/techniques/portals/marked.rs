//! Portals marked in a loaded scene by the names of its nodes (glTF node names, as
//! `engine::load::Loaded::names` gives them: root-to-node paths joined by `/`):
//!
//! - a node named `portal.<room>` marks an opening: its mesh is one planar quad (four
//!   distinct vertices, two triangles) whose front face (counter-clockwise, glTF's
//!   convention) looks toward the near side. It is a marker and is not drawn;
//! - the instances of a node named `room.<room>`, and of every node below it, are what is
//!   seen through the opening `portal.<room>`;
//! - everything else is near geometry, drawn as usual.
//!
//! A room without its portal, a portal without its room, or a portal mesh that is not a
//! planar quad is an error naming the node.

use super::{Opening, Portal};
use crate::core::MeshGroup;
use engine::Scene;
use glam::Vec3;
use std::collections::BTreeMap;

/// Why a scene's portal markers cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MarkError {
    /// The names given are not one per instance of the scene.
    #[error("{names} names for {instances} instances: give one name per instance")]
    Names {
        /// Names given.
        names: usize,
        /// Instances in the scene.
        instances: usize,
    },
    /// A `portal.` node's mesh is missing or is not one quad (4 vertices, 2 triangles).
    #[error("portal node '{node}': {why}")]
    NotAQuad {
        /// The node's name.
        node: String,
        /// What is wrong with its mesh.
        why: String,
    },
    /// An opening with no `room.` node of the same name.
    #[error("portal '{room}' (node '{node}') has nothing behind it: no node named 'room.{room}'")]
    NoRoom {
        /// The room's name (what follows `portal.`).
        room: String,
        /// The opening's node.
        node: String,
    },
    /// A room with no `portal.` node of the same name.
    #[error("room '{room}' (node '{node}') has no opening: no node named 'portal.{room}'")]
    NoPortal {
        /// The room's name (what follows `room.`).
        room: String,
        /// The room's node.
        node: String,
    },
    /// Two `portal.` nodes for one room.
    #[error("two nodes mark the opening of '{room}': '{first}' and '{second}'")]
    TwoPortals {
        /// The room's name.
        room: String,
        /// The first node marking its opening.
        first: String,
        /// The second.
        second: String,
    },
}

/// A scene's portals and the instances drawn as near geometry.
#[derive(Debug)]
pub struct Marked {
    /// One per marked opening, in the order of the rooms' names.
    pub portals: Vec<Portal>,
    /// Instances that are neither an opening nor in a room.
    pub near: Vec<usize>,
}

/// What a name marks: the first `portal.` or `room.` segment of its path.
fn mark(name: &str) -> Option<(bool, &str)> {
    name.split('/').find_map(|seg| {
        seg.strip_prefix("portal.")
            .map(|r| (true, r))
            .or_else(|| seg.strip_prefix("room.").map(|r| (false, r)))
    })
}

/// Reads the portals marked in `scene` (`names[i]` names instance `i`).
pub fn from_scene(scene: &Scene, names: &[String]) -> Result<Marked, MarkError> {
    if names.len() != scene.instances.len() {
        return Err(MarkError::Names {
            names: names.len(),
            instances: scene.instances.len(),
        });
    }
    let mut openings: BTreeMap<&str, (Opening, &str)> = BTreeMap::new();
    let mut rooms: BTreeMap<&str, (Vec<usize>, &str)> = BTreeMap::new();
    let mut near = Vec::new();
    for (i, name) in names.iter().enumerate() {
        match mark(name) {
            Some((true, room)) => {
                let opening = quad(scene, i).map_err(|why| MarkError::NotAQuad {
                    node: name.clone(),
                    why,
                })?;
                if let Some((_, first)) = openings.insert(room, (opening, name)) {
                    return Err(MarkError::TwoPortals {
                        room: room.to_string(),
                        first: first.to_string(),
                        second: name.clone(),
                    });
                }
            }
            Some((false, room)) => rooms.entry(room).or_insert((Vec::new(), name)).0.push(i),
            None => near.push(i),
        }
    }
    if let Some((room, (_, node))) = rooms.iter().find(|(r, _)| !openings.contains_key(*r)) {
        return Err(MarkError::NoPortal {
            room: room.to_string(),
            node: node.to_string(),
        });
    }
    let portals = openings
        .into_iter()
        .map(|(room, (opening, node))| {
            let (instances, _) = rooms.get(room).ok_or_else(|| MarkError::NoRoom {
                room: room.to_string(),
                node: node.to_string(),
            })?;
            let behind = MeshGroup::from_scene(scene, instances.iter().copied());
            Ok(Portal::new(opening, behind))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Marked { portals, near })
}

/// Instance `i` as an opening: its four distinct world-space vertices, counter-clockwise
/// around their centre as seen from the side its first triangle faces.
fn quad(scene: &Scene, i: usize) -> Result<Opening, String> {
    let inst = &scene.instances[i];
    let mesh = scene
        .meshes
        .get(inst.mesh)
        .ok_or_else(|| "its mesh is missing".to_string())?;
    let mut corners: Vec<Vec3> = Vec::new();
    for p in &mesh.positions {
        let w = inst.transform.transform_point3(*p);
        if !w.is_finite() {
            return Err("a vertex is not finite".into());
        }
        if !corners
            .iter()
            .any(|c| c.distance(w) <= 1e-5 * (1.0 + w.length()))
        {
            corners.push(w);
        }
    }
    if corners.len() != 4 || mesh.indices.len() < 3 {
        return Err(format!(
            "a portal's mesh must be one quad (4 distinct vertices, 2 triangles); it has {} vertices and {} triangles",
            corners.len(),
            mesh.indices.len() / 3
        ));
    }
    let tri = |k: usize| {
        inst.transform
            .transform_point3(mesh.positions[mesh.indices[k] as usize])
    };
    let normal = (tri(1) - tri(0)).cross(tri(2) - tri(0)).normalize_or_zero();
    let center = corners.iter().copied().sum::<Vec3>() * 0.25;
    let size = corners
        .iter()
        .map(|c| c.distance(center))
        .fold(0.0, f32::max);
    if normal == Vec3::ZERO || size <= 0.0 {
        return Err("its first triangle has no area".into());
    }
    if corners
        .iter()
        .any(|c| (*c - center).dot(normal).abs() > 1e-3 * size)
    {
        return Err("its four vertices are not in one plane".into());
    }
    // Counter-clockwise about the normal.
    let u = (corners[0] - center).normalize_or_zero();
    let v = normal.cross(u);
    corners.sort_by(|a, b| {
        let angle = |p: &Vec3| (*p - center).dot(v).atan2((*p - center).dot(u));
        angle(a).total_cmp(&angle(b))
    });
    Ok(Opening {
        corners: [corners[0], corners[1], corners[2], corners[3]],
    })
}
