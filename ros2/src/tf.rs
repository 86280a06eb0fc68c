//! The robot's frames as a bag's TF says them (`/tf_static`, `/tf`: `tf2_msgs/TFMessage`): the
//! transforms between frames kept as a tree (each child frame's parent), and a sensor's mount
//! on the robot composed over the frames between them and projected onto the ground plane.

use std::collections::HashMap;

use crate::msgs::{Quaternion, TransformStamped, Vector3};

/// The most frames kept (a robot's TF tree has tens; a bag's frame names are at most
/// [`crate::bag::NAME_LIMIT`] bytes, so the tree stays under a few MiB).
pub const FRAME_LIMIT: usize = 4096;

/// A frame's name as TF compares them: ROS 1's tf wrote a leading `/` (`/base_link`), tf2
/// drops it.
#[must_use]
pub fn frame(name: &str) -> &str {
    name.trim_start_matches('/')
}

/// A rigid transform in 3-D: rotate by `rotation` (unit), then translate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rigid {
    /// Metres.
    pub translation: Vector3,
    /// A unit quaternion.
    pub rotation: Quaternion,
}

fn mul(a: Quaternion, b: Quaternion) -> Quaternion {
    Quaternion {
        w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
        x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
        y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
        z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
    }
}

fn conjugate(q: Quaternion) -> Quaternion {
    Quaternion {
        x: -q.x,
        y: -q.y,
        z: -q.z,
        w: q.w,
    }
}

/// `v` rotated by the unit quaternion `q` (q·v·q*).
fn rotate(q: Quaternion, v: Vector3) -> Vector3 {
    let p = Quaternion {
        x: v.x,
        y: v.y,
        z: v.z,
        w: 0.0,
    };
    let r = mul(mul(q, p), conjugate(q));
    Vector3 {
        x: r.x,
        y: r.y,
        z: r.z,
    }
}

impl Rigid {
    /// The identity.
    pub const IDENTITY: Self = Self {
        translation: Vector3 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
        },
        rotation: Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        },
    };

    /// A transform message's, its rotation normalised; `None` when a value is not finite or
    /// the rotation has no length (not a rotation).
    #[must_use]
    pub fn of(translation: Vector3, rotation: Quaternion) -> Option<Self> {
        let q = rotation;
        let norm = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
        let finite = [translation.x, translation.y, translation.z, norm]
            .iter()
            .all(|v| v.is_finite());
        if !finite || norm < 1e-9 {
            return None;
        }
        Some(Self {
            translation,
            rotation: Quaternion {
                x: q.x / norm,
                y: q.y / norm,
                z: q.z / norm,
                w: q.w / norm,
            },
        })
    }

    /// `self` then `next`: a point of `next`'s child frame in `self`'s parent frame.
    #[must_use]
    pub fn then(&self, next: &Self) -> Self {
        let moved = rotate(self.rotation, next.translation);
        Self {
            translation: Vector3 {
                x: self.translation.x + moved.x,
                y: self.translation.y + moved.y,
                z: self.translation.z + moved.z,
            },
            rotation: mul(self.rotation, next.rotation),
        }
    }

    /// The inverse transform.
    #[must_use]
    pub fn inverse(&self) -> Self {
        let q = conjugate(self.rotation);
        let t = rotate(q, self.translation);
        Self {
            translation: Vector3 {
                x: -t.x,
                y: -t.y,
                z: -t.z,
            },
            rotation: q,
        }
    }

    /// The angle between the child frame's z axis and the parent's, degrees: 0 for a frame
    /// level with its parent, 180 for one upside down.
    #[must_use]
    pub fn tilt_deg(&self) -> f64 {
        let z = rotate(
            self.rotation,
            Vector3 {
                x: 0.0,
                y: 0.0,
                z: 1.0,
            },
        );
        z.z.clamp(-1.0, 1.0).acos().to_degrees()
    }
}

/// Where an edge of the tree came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Source {
    /// `/tf_static` (latched, fixed).
    Static,
    /// `/tf`, the first transform of the pair seen.
    Dynamic,
}

/// A sensor's mount found in the tree.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// The sensor's frame in the base's.
    pub rigid: Rigid,
    /// Every edge composed came from `/tf_static` (else some came from `/tf`).
    pub all_static: bool,
}

/// The frames of a bag's TF: each child's parent and transform, the static ones apart from the
/// first of each pair seen on `/tf`.
#[derive(Debug, Default)]
pub struct Tree {
    edges: HashMap<(String, Source), (String, Rigid)>,
    /// Transforms not kept: not a rotation, or beyond [`FRAME_LIMIT`].
    pub dropped: u64,
}

impl Tree {
    /// Keeps a transform (of `/tf_static` when `source` is static): a static one replaces what
    /// the child had; of `/tf`, the first of each child is kept.
    pub fn add(&mut self, source: Source, t: &TransformStamped) {
        let Some(rigid) = Rigid::of(t.transform.translation, t.transform.rotation) else {
            self.dropped += 1;
            return;
        };
        let parent = frame(&t.header.frame_id).to_string();
        let key = (frame(&t.child_frame_id).to_string(), source);
        if parent == key.0 {
            self.dropped += 1;
            return;
        }
        let full = self.edges.len() >= FRAME_LIMIT;
        match self.edges.get_mut(&key) {
            Some(edge) if source == Source::Static => *edge = (parent, rigid),
            Some(_) => {}
            None if full => self.dropped += 1,
            None => {
                self.edges.insert(key, (parent, rigid));
            }
        }
    }

    /// Whether the tree has a frame of this name (as a parent or a child).
    #[must_use]
    pub fn has(&self, name: &str) -> bool {
        self.edges
            .iter()
            .any(|((child, _), (parent, _))| child == name || parent == name)
    }

    /// Whether any transform was kept.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// A frame's parent: the static edge, else the `/tf` one.
    fn parent(&self, child: &str) -> Option<(&str, &Rigid, Source)> {
        [Source::Static, Source::Dynamic].into_iter().find_map(|s| {
            self.edges
                .get(&(child.to_string(), s))
                .map(|(p, r)| (p.as_str(), r, s))
        })
    }

    /// `name`'s ancestors from itself up to its root: each frame, `name` in that frame, and
    /// whether every edge up to it was static.
    fn ancestors(&self, name: &str) -> Vec<(String, Rigid, bool)> {
        let mut chain = vec![(name.to_string(), Rigid::IDENTITY, true)];
        // A cycle (a bag's TF can say anything) ends after as many steps as there are edges.
        for _ in 0..self.edges.len() {
            let Some((at, rigid, all_static)) = chain.last() else {
                break;
            };
            let Some((parent, edge, source)) = self.parent(at) else {
                break;
            };
            let next = (
                parent.to_string(),
                edge.then(rigid),
                *all_static && source == Source::Static,
            );
            chain.push(next);
        }
        chain
    }

    /// `sensor`'s frame in `base`'s, composed over the frames between them (up to the first
    /// frame both descend from); `None` when the two are not in one tree.
    #[must_use]
    pub fn mount(&self, base: &str, sensor: &str) -> Option<Found> {
        if !(self.has(base) && self.has(sensor)) {
            return None;
        }
        let sensor_up = self.ancestors(sensor);
        for (frame, base_in, base_static) in self.ancestors(base) {
            if let Some((_, sensor_in, sensor_static)) =
                sensor_up.iter().find(|(f, _, _)| *f == frame)
            {
                return Some(Found {
                    rigid: base_in.inverse().then(sensor_in),
                    all_static: base_static && *sensor_static,
                });
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::{Header, Transform};

    fn edge(parent: &str, child: &str, x: f64, y: f64, yaw: f64) -> TransformStamped {
        TransformStamped {
            header: Header {
                frame_id: parent.into(),
                ..Header::default()
            },
            child_frame_id: child.into(),
            transform: Transform {
                translation: Vector3 { x, y, z: 0.1 },
                rotation: Quaternion::from_yaw(yaw),
            },
        }
    }

    /// base_footprint → base_link → plate → laser composes as the 2-D poses do, seen from
    /// base_link or from base_footprint; a sibling branch shares the root.
    #[test]
    fn a_mount_composes_over_intermediate_frames() {
        let mut tree = Tree::default();
        tree.add(
            Source::Static,
            &edge("base_footprint", "base_link", 0.0, 0.0, 0.0),
        );
        tree.add(Source::Static, &edge("/base_link", "plate", 0.1, 0.0, 0.5));
        tree.add(Source::Static, &edge("plate", "laser", 0.2, 0.0, 1.0));
        tree.add(
            Source::Static,
            &edge("base_footprint", "sonar", -0.1, 0.0, 0.0),
        );
        let found = tree.mount("base_link", "laser").unwrap();
        assert!(found.all_static);
        let r = found.rigid;
        assert!((r.translation.x - (0.1 + 0.2 * 0.5f64.cos())).abs() < 1e-12);
        assert!((r.translation.y - 0.2 * 0.5f64.sin()).abs() < 1e-12);
        assert!((r.rotation.yaw() - 1.5).abs() < 1e-12);
        let from_sonar = tree.mount("sonar", "laser").unwrap().rigid;
        assert!((from_sonar.translation.x - (r.translation.x + 0.1)).abs() < 1e-12);
        assert!(tree.mount("base_link", "camera").is_none());
        assert!(r.tilt_deg() < 1e-6);
    }

    /// A static transform wins over /tf's; /tf's first is kept; a cycle ends.
    #[test]
    fn static_edges_win_and_cycles_end() {
        let mut tree = Tree::default();
        tree.add(Source::Dynamic, &edge("base_link", "laser", 1.0, 0.0, 0.0));
        tree.add(Source::Dynamic, &edge("base_link", "laser", 2.0, 0.0, 0.0));
        let found = tree.mount("base_link", "laser").unwrap();
        assert_eq!((found.rigid.translation.x, found.all_static), (1.0, false));
        tree.add(Source::Static, &edge("base_link", "laser", 3.0, 0.0, 0.0));
        assert_eq!(
            tree.mount("base_link", "laser")
                .unwrap()
                .rigid
                .translation
                .x,
            3.0
        );
        tree.add(Source::Static, &edge("laser", "base_link", 0.0, 0.0, 0.0));
        let _ = tree.mount("base_link", "laser");
        // Frames below a moving one: the moving edge is not composed.
        let mut moving = Tree::default();
        moving.add(Source::Dynamic, &edge("odom", "base_link", 5.0, 1.0, 2.0));
        moving.add(Source::Static, &edge("base_link", "laser", 0.1, 0.0, 0.0));
        let found = moving.mount("base_link", "laser").unwrap();
        assert_eq!((found.rigid.translation.x, found.all_static), (0.1, true));
        let mut flat = edge("a", "b", 0.0, 0.0, 0.0);
        flat.transform.rotation = Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 0.0,
        };
        tree.add(Source::Static, &flat);
        assert_eq!(tree.dropped, 1);
    }

    #[test]
    fn an_upside_down_frame_is_tilted_180_degrees() {
        let roll = Rigid::of(
            Vector3::default(),
            Quaternion {
                x: 1.0,
                y: 0.0,
                z: 0.0,
                w: 0.0,
            },
        )
        .unwrap();
        assert!((roll.tilt_deg() - 180.0).abs() < 1e-9);
        let back = roll.then(&roll.inverse());
        assert!(back.tilt_deg() < 1e-6);
    }
}
