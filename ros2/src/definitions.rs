//! The `ros2msg` text of each message hilsim writes: what an MCAP schema carries so that a tool
//! without ROS installed (Foxglove, `mcap-ros2-support`, `rosbags`) can decode the CDR. As ROS 2
//! Humble and Jazzy define them (`common_interfaces`), comments dropped, every type
//! package-qualified; a message's definition is followed by each type it uses, once, after a
//! line of 80 `=` and `MSG: package/Type` (the MCAP registry's `ros2msg` encoding).

const TIME: &str = "int32 sec\nuint32 nanosec\n";
const HEADER: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
const VECTOR3: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const QUATERNION: &str = "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
const POSE: &str = "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n";
const TWIST: &str = "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n";
const TRANSFORM: &str = "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n";

/// The message types hilsim writes, by their full name.
const TYPES: &[(&str, &str)] = &[
    ("builtin_interfaces/Time", TIME),
    ("builtin_interfaces/Duration", TIME),
    ("std_msgs/Header", HEADER),
    (
        "std_msgs/ColorRGBA",
        "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    ),
    ("geometry_msgs/Vector3", VECTOR3),
    ("geometry_msgs/Point", VECTOR3),
    ("geometry_msgs/Quaternion", QUATERNION),
    ("geometry_msgs/Pose", POSE),
    ("geometry_msgs/Twist", TWIST),
    ("geometry_msgs/Transform", TRANSFORM),
    (
        "geometry_msgs/PoseWithCovariance",
        "geometry_msgs/Pose pose\nfloat64[36] covariance\n",
    ),
    (
        "geometry_msgs/TwistWithCovariance",
        "geometry_msgs/Twist twist\nfloat64[36] covariance\n",
    ),
    (
        "geometry_msgs/PoseStamped",
        "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
    ),
    (
        "geometry_msgs/TwistStamped",
        "std_msgs/Header header\ngeometry_msgs/Twist twist\n",
    ),
    (
        "geometry_msgs/TransformStamped",
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
    ),
    (
        "tf2_msgs/TFMessage",
        "geometry_msgs/TransformStamped[] transforms\n",
    ),
    (
        "nav_msgs/Odometry",
        "std_msgs/Header header\nstring child_frame_id\n\
         geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist\n",
    ),
    (
        "sensor_msgs/LaserScan",
        "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\n\
         float32 angle_increment\nfloat32 time_increment\nfloat32 scan_time\n\
         float32 range_min\nfloat32 range_max\nfloat32[] ranges\nfloat32[] intensities\n",
    ),
    (
        "sensor_msgs/Range",
        "uint8 ULTRASOUND=0\nuint8 INFRARED=1\nstd_msgs/Header header\nuint8 radiation_type\n\
         float32 field_of_view\nfloat32 min_range\nfloat32 max_range\nfloat32 range\n",
    ),
    (
        "sensor_msgs/CompressedImage",
        "std_msgs/Header header\nstring format\nuint8[] data\n",
    ),
    ("visualization_msgs/UVCoordinate", "float32 u\nfloat32 v\n"),
    (
        "visualization_msgs/MeshFile",
        "string filename\nuint8[] data\n",
    ),
    (
        "visualization_msgs/Marker",
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
         int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
         int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n\
         int32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n\
         std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n\
         geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
         builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
         std_msgs/ColorRGBA[] colors\nstring texture_resource\n\
         sensor_msgs/CompressedImage texture\nvisualization_msgs/UVCoordinate[] uv_coordinates\n\
         string text\nstring mesh_resource\nvisualization_msgs/MeshFile mesh_file\n\
         bool mesh_use_embedded_materials\n",
    ),
    (
        "visualization_msgs/MarkerArray",
        "visualization_msgs/Marker[] markers\n",
    ),
];

fn own_text(name: &str) -> Option<&'static str> {
    TYPES.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// The package-qualified types a definition's fields use, in order of appearance.
fn used_types(text: &str) -> impl Iterator<Item = &str> {
    text.lines().filter_map(|line| {
        let field_type = line.split_whitespace().next()?;
        let base = field_type.split('[').next()?;
        base.contains('/').then_some(base)
    })
}

/// The `ros2msg` schema text of `name` (e.g. `sensor_msgs/msg/LaserScan`): its definition and
/// every type it uses, depth first. `None` for a type hilsim does not write.
#[must_use]
pub fn schema_text(name: &str) -> Option<String> {
    let name = name.replace("/msg/", "/");
    let mut text = own_text(&name)?.to_string();
    let mut done = vec![name.clone()];
    let mut todo: Vec<String> = used_types(own_text(&name)?).map(str::to_string).collect();
    todo.reverse();
    while let Some(dep) = todo.pop() {
        if done.contains(&dep) {
            continue;
        }
        let dep_text = own_text(&dep)?;
        text.push_str(&"=".repeat(80));
        text.push_str("\nMSG: ");
        text.push_str(&dep);
        text.push('\n');
        text.push_str(dep_text);
        let mut more: Vec<String> = used_types(dep_text).map(str::to_string).collect();
        more.reverse();
        todo.extend(more);
        done.push(dep);
    }
    Some(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_type_used_is_defined_once() {
        for (name, _) in TYPES {
            let text = schema_text(name).unwrap();
            let mut seen = vec![name.to_string()];
            for line in text.lines().filter_map(|l| l.strip_prefix("MSG: ")) {
                assert!(!seen.contains(&line.to_string()), "{name}: {line} twice");
                seen.push(line.to_string());
            }
            for used in used_types(&text) {
                assert!(seen.iter().any(|s| s == used), "{name}: {used} undefined");
            }
        }
    }

    #[test]
    fn a_laser_scan_carries_its_header_and_time() {
        let text = schema_text("sensor_msgs/msg/LaserScan").unwrap();
        assert!(text.starts_with("std_msgs/Header header\n"));
        assert!(text.contains("\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\n"));
        assert!(text.ends_with("MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"));
        assert!(schema_text("sensor_msgs/msg/Image").is_none());
    }
}
