//! Where the robot's disc fits among the world's obstacles: a scenario's start must be clear of
//! them, and a run whose robot would pass through one is not a run a robot could make.

use super::validate::segment_distance;
use super::Scenario;
use crate::world::Obstacle;

/// An obstacle the robot's disc overlaps: which, and how far the disc's centre is from its
/// surface (less than the robot's radius; zero or less inside it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overlap {
    /// What the disc overlaps.
    pub obstacle: Obstacle,
    /// Distance from the disc's centre to the obstacle's surface, metres.
    pub clearance_m: f64,
}

impl Scenario {
    /// The first obstacle (walls, then cylinders, then boards) that the robot's disc
    /// (`robot.radius_m`) centred at `at` overlaps, if any. Touching is clear.
    #[must_use]
    pub fn robot_overlap(&self, at: [f64; 2]) -> Option<Overlap> {
        let r = self.robot.radius_m;
        let walls = self
            .world
            .walls
            .iter()
            .enumerate()
            .map(|(i, w)| (Obstacle::Wall(i), segment_distance(at, w.from, w.to)));
        let cylinders = self.world.cylinders.iter().enumerate().map(|(i, c)| {
            let centre = (at[0] - c.center[0]).hypot(at[1] - c.center[1]);
            (Obstacle::Cylinder(i), centre - c.radius)
        });
        let boards = self.world.boards.iter().enumerate().map(|(i, b)| {
            // Distance to the board's rectangle, in its own frame.
            let (sin, cos) = b.yaw_deg.to_radians().sin_cos();
            let (dx, dy) = (at[0] - b.center[0], at[1] - b.center[1]);
            let along = (dx * cos + dy * sin).abs() - b.length / 2.0;
            let across = (-dx * sin + dy * cos).abs() - b.thickness / 2.0;
            let outside = along.max(0.0).hypot(across.max(0.0));
            // Inside the rectangle: minus the depth to its nearest side.
            let inside = along.max(across).min(0.0);
            (Obstacle::Board(i), outside + inside)
        });
        walls
            .chain(cylinders)
            .chain(boards)
            .find(|&(_, clearance_m)| clearance_m < r)
            .map(|(obstacle, clearance_m)| Overlap {
                obstacle,
                clearance_m,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn room() -> Scenario {
        Scenario::from_toml(
            r#"
            name = "clearance"
            duration_s = 1.0
            [world]
            walls = [{ from = [0.0, 0.0], to = [4.0, 0.0] }]
            cylinders = [{ center = [2.0, 2.0], radius = 0.1 }]
            boards = [{ center = [3.0, 1.0], length = 0.8, thickness = 0.02, yaw_deg = 90.0 }]
            [robot]
            start = { x = 1.0, y = 1.0 }
            radius_m = 0.2
            wheel_base_m = 0.23
            "#,
            "clearance.toml".as_ref(),
        )
        .unwrap()
    }

    #[test]
    fn the_disc_overlaps_what_is_nearer_than_its_radius() {
        let s = room();
        assert_eq!(s.robot_overlap([1.0, 1.0]), None);
        // 0.15 m above the wall, and below it (through it).
        let wall = s.robot_overlap([1.0, 0.15]).unwrap();
        assert_eq!(wall.obstacle, Obstacle::Wall(0));
        assert!((wall.clearance_m - 0.15).abs() < 1e-12);
        assert_eq!(
            s.robot_overlap([1.0, -0.1]).map(|o| o.obstacle),
            Some(Obstacle::Wall(0))
        );
        // 0.25 m from the cylinder's centre: 0.15 m from its surface.
        assert_eq!(
            s.robot_overlap([2.25, 2.0]).map(|o| o.obstacle),
            Some(Obstacle::Cylinder(0))
        );
        assert_eq!(s.robot_overlap([2.35, 2.0]), None);
        // The board stands along y from 0.6 to 1.4 at x = 3: its face is 0.01 m from x = 3.
        assert_eq!(s.robot_overlap([2.7, 1.0]), None);
        let board = s.robot_overlap([2.8, 1.0]).unwrap();
        assert_eq!(board.obstacle, Obstacle::Board(0));
        assert!((board.clearance_m - 0.19).abs() < 1e-9);
        // Inside the board's rectangle the clearance is negative.
        assert!(s.robot_overlap([3.0, 1.0]).unwrap().clearance_m < 0.0);
        // Beyond the board's end.
        assert_eq!(s.robot_overlap([3.0, 1.65]), None);
    }
}
