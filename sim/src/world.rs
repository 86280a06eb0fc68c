//! The static world and the robot's body in a rapier2d physics world, seen from above: no
//! gravity, obstacles fixed, the robot a dynamic disc driven by wheel speeds.
//!
//! rapier works in `f32` glam types; everything public here is `f64` in SI units.

use rapier2d::prelude::*;

use crate::occupancy::OccupancyMap;
use crate::scenario::Scenario;
use hilsim_recording::pose::Pose;

/// What a collider is, so a sensor can ask what it hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Obstacle {
    /// `world.walls[i]`.
    Wall(usize),
    /// `world.cylinders[i]`.
    Cylinder(usize),
    /// `world.boards[i]`.
    Board(usize),
    /// An occupied cell of `world.map`.
    Map,
}

/// A ray's first hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// Distance along the ray, metres.
    pub distance: f64,
    /// What was hit.
    pub obstacle: Obstacle,
    /// Surface normal at the hit, world frame, unit length.
    pub normal: [f64; 2],
    /// The surface material's reflectivity, (0, 1].
    pub reflectivity: f64,
    /// How far the surface may be from where the world puts it, along its normal and across
    /// the beam, metres: 0 for a scenario's drawn shapes, a cell for a map's (the surface
    /// anywhere across its cell, and a map's rasterised outline a cell fatter or thinner than
    /// the object).
    pub surface_uncertainty_m: f64,
}

/// The physics world: obstacles plus the robot's body.
pub struct World {
    pub(crate) physics: PhysicsWorld,
    pub(crate) robot: RigidBodyHandle,
    robot_collider: ColliderHandle,
    /// Per obstacle collider (indexed by `user_data`): what it is and its reflectivity.
    obstacles: Vec<(Obstacle, f64)>,
    /// The obstacles as rays see them (see [`World::cast_ray`]).
    fixed: Vec<FixedShape>,
    /// `[world] map` (rays only: the robot's body passes through its cells) and its cells'
    /// reflectivity.
    map: Option<(std::sync::Arc<OccupancyMap>, f64)>,
}

/// An obstacle's collider with a circle around it, to skip it cheaply for a ray that passes
/// wide of it.
struct FixedShape {
    collider: ColliderHandle,
    center: Vector,
    radius: f32,
    /// A wall's two ends, world frame: a ray whose line passes both on one side misses it.
    ends: Option<[Vector; 2]>,
}

impl FixedShape {
    /// Whether a ray from `origin` along `dir` (unit) cannot hit the shape before `nearest`.
    /// Every test leaves a margin for `f32` rounding: a "maybe" only costs the exact cast.
    fn is_missed(&self, origin: Vector, dir: Vector, nearest: f32) -> bool {
        let to_center = self.center - origin;
        let along = to_center.dot(dir);
        let beside_sq = to_center.length_squared() - along * along;
        if along + self.radius < 0.0
            || along - self.radius >= nearest
            || beside_sq > self.radius * self.radius
        {
            return true;
        }
        let Some([a, b]) = self.ends else {
            return false;
        };
        let (to_a, to_b) = (a - origin, b - origin);
        let margin = 1e-4 * (to_a.length() + to_b.length()) + 1e-6;
        // Both ends on one side of the ray's line; both behind it; both beyond `nearest` (a
        // point of the segment is as far along the ray as a mix of its ends).
        let (side_a, side_b) = (dir.perp_dot(to_a), dir.perp_dot(to_b));
        let (along_a, along_b) = (dir.dot(to_a), dir.dot(to_b));
        (side_a > margin && side_b > margin)
            || (side_a < -margin && side_b < -margin)
            || along_a.max(along_b) < -margin
            || along_a.min(along_b) > nearest + margin
    }
}

impl World {
    /// Builds the world of a validated scenario with the robot at its start pose.
    #[must_use]
    pub fn new(scenario: &Scenario) -> Self {
        // Seen from above: no gravity.
        let mut physics = PhysicsWorld {
            gravity: Vector::ZERO,
            ..PhysicsWorld::default()
        };
        physics.integration_parameters.dt = scenario.step_s() as f32;
        let mut obstacles = Vec::new();
        let fixed = physics.insert_body(RigidBodyBuilder::fixed());
        let mut add = |physics: &mut PhysicsWorld,
                       builder: ColliderBuilder,
                       what,
                       material: Option<&String>| {
            let collider = builder
                .user_data(obstacles.len() as u128)
                .friction(0.0)
                .build();
            obstacles.push((what, scenario.reflectivity(material.map(String::as_str))));
            physics.insert_collider(collider, Some(fixed));
        };
        let w = &scenario.world;
        for (i, wall) in w.walls.iter().enumerate() {
            let builder = ColliderBuilder::segment(vec2(wall.from), vec2(wall.to));
            add(
                &mut physics,
                builder,
                Obstacle::Wall(i),
                wall.material.as_ref(),
            );
        }
        for (i, c) in w.cylinders.iter().enumerate() {
            let builder = ColliderBuilder::ball(c.radius as f32).translation(vec2(c.center));
            add(
                &mut physics,
                builder,
                Obstacle::Cylinder(i),
                c.material.as_ref(),
            );
        }
        for (i, b) in w.boards.iter().enumerate() {
            let builder =
                ColliderBuilder::cuboid((b.length / 2.0) as f32, (b.thickness / 2.0) as f32)
                    .translation(vec2(b.center))
                    .rotation(b.yaw_deg.to_radians() as f32);
            add(
                &mut physics,
                builder,
                Obstacle::Board(i),
                b.material.as_ref(),
            );
        }
        let start = scenario.robot.start;
        let (robot, robot_collider) = physics.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(start.x as f32, start.y as f32))
                .rotation(start.yaw_deg.to_radians() as f32)
                .can_sleep(false)
                // Fast, thin walls: sweep the robot so it cannot tunnel through a segment.
                .ccd_enabled(true),
            ColliderBuilder::ball(scenario.robot.radius_m as f32)
                .friction(0.0)
                .active_events(ActiveEvents::COLLISION_EVENTS),
        );
        // Fill the broad phase now so that contacts are known before the first step.
        physics.detect_collisions(&(), &());
        let fixed = physics
            .colliders
            .iter()
            .filter(|(handle, _)| *handle != robot_collider)
            .map(|(collider, co)| {
                let sphere = co.shape().compute_bounding_sphere(co.position());
                let ends = co.shape().as_segment().map(|segment| {
                    [segment.a, segment.b].map(|end| co.position().transform_point(end))
                });
                FixedShape {
                    collider,
                    center: sphere.center,
                    // f32 rounding in the tests must never skip a grazing hit.
                    radius: sphere.radius * (1.0 + 1e-4) + 1e-4,
                    ends,
                }
            })
            .collect();
        Self {
            physics,
            robot,
            robot_collider,
            obstacles,
            fixed,
            map: scenario
                .files
                .map
                .clone()
                .map(|map| (map, scenario.reflectivity(None))),
        }
    }

    /// The robot's pose now.
    #[must_use]
    pub fn robot_pose(&self) -> Pose {
        let body = &self.physics.bodies[self.robot];
        let t = body.translation();
        Pose::new(
            f64::from(t.x),
            f64::from(t.y),
            f64::from(body.rotation().angle()),
        )
    }

    /// How far the world's surfaces may be from where it puts them, metres: half a cell of its
    /// map (the surface anywhere across a cell), 0 for drawn shapes alone.
    #[must_use]
    pub fn surface_uncertainty_m(&self) -> f64 {
        self.map
            .as_ref()
            .map_or(0.0, |(m, _)| m.resolution_m() / 2.0)
    }

    /// Puts the robot at `pose`, at rest: a recorded path moves it (the physics then finds its
    /// contacts there, not its motion).
    pub(crate) fn place_robot(&mut self, pose: Pose) {
        let body = &mut self.physics.bodies[self.robot];
        body.set_position(
            Pose2::new(Vector::new(pose.x as f32, pose.y as f32), pose.yaw as f32),
            true,
        );
        body.set_linvel(Vector::ZERO, true);
        body.set_angvel(0.0, true);
    }

    /// Casts a ray from `origin` along `heading_rad` (world frame) up to `max_m`, ignoring the
    /// robot's own body. Static obstacles do not move, so the answer does not depend on when
    /// within a physics step it is asked.
    ///
    /// The ray is cast against each obstacle's own shape, as rapier's query pipeline does after
    /// its broad phase, with the same `f32` arithmetic and so the same hits; a world holds
    /// tens of obstacles, and cheap tests that skip most of them are twice as fast as the
    /// broad phase's tree (which also holds the moving robot). Of two obstacles hit at exactly
    /// the same distance (a corner), the one added first is reported.
    #[must_use]
    pub fn cast_ray(&self, origin: [f64; 2], heading_rad: f64, max_m: f64) -> Option<RayHit> {
        let (sin, cos) = heading_rad.sin_cos();
        self.cast_ray_along(origin, [cos, sin], max_m)
    }

    /// [`World::cast_ray`] along the unit direction `[cos, sin]` of the heading, for a caller
    /// that needs the direction itself too (the beam's incidence) and so computes it once.
    #[must_use]
    pub fn cast_ray_along(
        &self,
        origin: [f64; 2],
        direction: [f64; 2],
        max_m: f64,
    ) -> Option<RayHit> {
        let ray = Ray::new(vec2(origin), vec2(direction));
        let mut nearest = max_m as f32;
        let mut best = None;
        for shape in &self.fixed {
            if shape.is_missed(ray.origin, ray.dir, nearest) {
                continue;
            }
            let Some(co) = self.physics.colliders.get(shape.collider) else {
                continue;
            };
            if let Some(hit) =
                co.shape()
                    .cast_ray_and_get_normal(co.position(), &ray, nearest, true)
            {
                if hit.time_of_impact < nearest {
                    nearest = hit.time_of_impact;
                    best = Some((shape.collider, hit));
                }
            }
        }
        let shape_hit = best.and_then(|(handle, hit)| {
            let (obstacle, reflectivity) = self.obstacle_of(handle)?;
            Some(RayHit {
                distance: f64::from(hit.time_of_impact),
                obstacle,
                normal: [f64::from(hit.normal.x), f64::from(hit.normal.y)],
                reflectivity,
                surface_uncertainty_m: 0.0,
            })
        });
        let Some((map, reflectivity)) = &self.map else {
            return shape_hit;
        };
        let within = shape_hit.map_or(max_m, |h| h.distance);
        match map.cast_ray(origin, direction, within) {
            Some(cell) if cell.surface_m < within => Some(RayHit {
                distance: cell.surface_m,
                obstacle: Obstacle::Map,
                normal: cell.normal,
                reflectivity: *reflectivity,
                surface_uncertainty_m: map.resolution_m(),
            }),
            _ => shape_hit,
        }
    }

    fn obstacle_of(&self, handle: ColliderHandle) -> Option<(Obstacle, f64)> {
        let index = self.physics.colliders.get(handle)?.user_data as usize;
        self.obstacles.get(index).copied()
    }

    /// What a collider handle refers to, if it is an obstacle.
    pub(crate) fn obstacle(&self, handle: ColliderHandle) -> Option<Obstacle> {
        if handle == self.robot_collider {
            return None;
        }
        self.obstacle_of(handle).map(|(o, _)| o)
    }

    /// The robot's collider.
    pub(crate) fn robot_collider(&self) -> ColliderHandle {
        self.robot_collider
    }
}

fn vec2(p: [f64; 2]) -> Vector {
    Vector::new(p[0] as f32, p[1] as f32)
}
