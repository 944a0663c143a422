//! Scene text moved by editing it, as a user would move a scene: shared by
//! the integration tests (`common`) and the loader's unit tests, which
//! include this file by its path.

/// The keys whose values are points (read in f64 and rebased by the loader).
pub const POINT_KEYS: [&str; 8] = [
    "position",
    "look_at",
    "grid_min",
    "grid_max",
    "corner",
    "base",
    "center",
    "translate",
];

/// A scene file's text with every point written on one line as
/// `key = [x, y, z]` moved by `t`, as a user would move a scene by editing
/// its file; and how many points it moved.
pub fn moved_scene_text(text: &str, t: glam::DVec3) -> (String, usize) {
    let mut moved = 0;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            let Some((key, value)) = line.split_once('=') else {
                return line.to_string();
            };
            let (value, comment) = value.split_once('#').unwrap_or((value, ""));
            let inner = value
                .trim()
                .strip_prefix('[')
                .and_then(|v| v.strip_suffix(']'));
            let (Some(inner), true) = (inner, POINT_KEYS.contains(&key.trim())) else {
                return line.to_string();
            };
            let p: Vec<f64> = inner
                .split(',')
                .map(|x| x.trim().parse().unwrap())
                .collect();
            assert_eq!(p.len(), 3, "{line}");
            moved += 1;
            let p = glam::DVec3::new(p[0], p[1], p[2]) + t;
            let comment = if comment.is_empty() {
                String::new()
            } else {
                format!(" #{comment}")
            };
            format!("{key}= [{:?}, {:?}, {:?}]{comment}", p.x, p.y, p.z)
        })
        .collect();
    (lines.join("\n") + "\n", moved)
}
