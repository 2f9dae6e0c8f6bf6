//! `fray view` under Xvfb: the window opens, its still frame on the screen is `fray render`'s
//! for the same camera, it answers synthetic input (xdotool: a right drag turns, W flies), and the save key writes
//! the bytes `fray render` writes for the camera it prints. Reported as *ignored* where Xvfb,
//! xwd, xdotool or a Vulkan adapter is missing, unless `FRAY_REQUIRE_GPU=1` (CI), which makes
//! a missing one a failure.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

const FRAY: &str = env!("CARGO_BIN_EXE_fray");
const SIZE: (u32, u32) = (320, 240);
/// How long a step may take: a debug build on a loaded two-core machine with lavapipe.
const PATIENCE: Duration = Duration::from_secs(240);

/// A small scene whose camera is one line, so a printed camera snippet can replace it.
const SCENE: &str = r#"Scene(
  image: (width: 320, height: 240),
  camera: Pinhole(eye: (0, 1.5, -6), look_at: (0, 0.8, 0)),
  background: (0.3, 0.4, 0.6),
  ambient: (0.1, 0.1, 0.1),
  lights: [ Sun(direction: (-0.5, 0.8, -0.4), irradiance: (2.5, 2.5, 2.4)) ],
  materials: { "red": (diffuse: (0.8, 0.2, 0.1)), "grey": (diffuse: (0.5, 0.5, 0.5)) },
  objects: [
    (material: "red", shape: Sphere(center: (0, 1, 0), radius: 1)),
    (material: "grey", shape: Sphere(center: (0, -100, 0), radius: 100)),
  ],
)
"#;

/// What is missing for these tests, if anything.
fn missing() -> Option<String> {
    for tool in ["Xvfb", "xwd", "xdotool"] {
        let found = Command::new("sh")
            .args(["-c", &format!("command -v {tool}")])
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if !found {
            return Some(format!("{tool} is not installed"));
        }
    }
    let vulkan = ["/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d"]
        .iter()
        .any(|d| std::fs::read_dir(d).is_ok_and(|mut e| e.next().is_some()));
    (!vulkan).then(|| "no Vulkan driver (e.g. lavapipe) is installed".to_owned())
}

/// An Xvfb server on a display it chose, killed when dropped.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Self {
        let screen = format!("{}x{}x24", SIZE.0, SIZE.1);
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                &screen,
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb starts");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("Xvfb's stdout"))
            .read_line(&mut line)
            .expect("Xvfb prints its display");
        let number: u32 = line.trim().parse().expect("a display number");
        Self {
            child,
            display: format!(":{number}"),
        }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The viewer's process and its stdout, line by line.
struct Viewer {
    child: Child,
    lines: Receiver<String>,
    seen: Vec<String>,
}

impl Viewer {
    fn start(x: &Xvfb, dir: &Path, scene: &Path, backend: &str) -> Self {
        Self::start_with(x, dir, scene, backend, &[])
    }

    /// [`Viewer::start`] with more arguments.
    fn start_with(x: &Xvfb, dir: &Path, scene: &Path, backend: &str, extra: &[&str]) -> Self {
        let runtime = dir.join("xdg");
        std::fs::create_dir_all(&runtime).unwrap();
        let size = format!("{}x{}", SIZE.0, SIZE.1);
        let mut child = Command::new(FRAY)
            .arg("view")
            .arg(scene)
            .args(["--size", &size, "--backend", backend, "--threads", "2"])
            .args(["--samples", "1", "--no-overlay", "--exit-after-save"])
            .arg("--save-as")
            .arg(dir.join("saved.png"))
            .args(extra)
            .env("DISPLAY", &x.display)
            .env("XDG_RUNTIME_DIR", &runtime)
            .stdout(Stdio::piped())
            .spawn()
            .expect("fray view starts");
        let stdout = child.stdout.take().expect("the viewer's stdout");
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                eprintln!("viewer: {line}");
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Self {
            child,
            lines,
            seen: Vec::new(),
        }
    }

    /// Waits for a line starting with `prefix` (after those already seen) and returns it.
    fn wait_for(&mut self, prefix: &str) -> String {
        let deadline = Instant::now() + PATIENCE;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    self.seen.push(line.clone());
                    if line.starts_with(prefix) {
                        return line;
                    }
                }
                Err(_) => panic!(
                    "no {prefix:?} line from the viewer in {PATIENCE:?}; it printed {:?} (exit: {:?})",
                    self.seen,
                    self.child.try_wait()
                ),
            }
        }
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The screen as RGB bytes, row by row, from `xwd -root` (a 24-bit TrueColor ZPixmap).
fn screenshot(x: &Xvfb) -> Vec<[u8; 3]> {
    let out = Command::new("xwd")
        .args(["-root", "-silent", "-display", &x.display])
        .output()
        .expect("xwd runs");
    assert!(out.status.success(), "xwd failed");
    let d = out.stdout;
    let word = |i: usize| u32::from_be_bytes(d[4 * i..4 * i + 4].try_into().unwrap());
    let (header, width, height) = (word(0) as usize, word(4), word(5));
    let (lsb_first, bits, bytes_per_line, colours) =
        (word(7) == 0, word(11), word(12) as usize, word(19) as usize);
    let (red, green, blue) = (word(14), word(15), word(16));
    assert_eq!((width, height, bits), (SIZE.0, SIZE.1, 32), "the screen");
    let start = header + 12 * colours;
    let channel = |v: u32, mask: u32| ((v & mask) >> mask.trailing_zeros()) as u8;
    let mut pixels = Vec::with_capacity((width * height) as usize);
    for y in 0..height as usize {
        for x in 0..width as usize {
            let at = start + y * bytes_per_line + 4 * x;
            let b: [u8; 4] = d[at..at + 4].try_into().unwrap();
            let v = if lsb_first {
                u32::from_le_bytes(b)
            } else {
                u32::from_be_bytes(b)
            };
            pixels.push([channel(v, red), channel(v, green), channel(v, blue)]);
        }
    }
    pixels
}

/// `fray render` of `scene` on `backend` at the window's size, as RGB bytes.
fn render(dir: &Path, scene: &Path, backend: &str, name: &str) -> Vec<[u8; 3]> {
    let out = dir.join(name);
    let status = Command::new(FRAY)
        .arg("render")
        .arg(scene)
        .args(["--backend", backend, "--samples", "1", "-q"])
        .args([
            "--width",
            &SIZE.0.to_string(),
            "--height",
            &SIZE.1.to_string(),
        ])
        .arg("-o")
        .arg(&out)
        .env("XDG_RUNTIME_DIR", dir.join("xdg"))
        .status()
        .expect("fray render runs");
    assert!(status.success(), "fray render {}", scene.display());
    png(&out)
}

fn png(path: &Path) -> Vec<[u8; 3]> {
    let image = image::open(path).expect("a PNG").to_rgb8();
    image.pixels().map(|p| p.0).collect()
}

/// The largest difference of any channel, and the fraction of pixels more than 2 code values
/// apart.
fn difference(a: &[[u8; 3]], b: &[[u8; 3]]) -> (u8, f64) {
    assert_eq!(a.len(), b.len());
    let per_pixel: Vec<u8> = a
        .iter()
        .zip(b)
        .map(|(p, q)| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0))
        .collect();
    let worst = per_pixel.iter().copied().max().unwrap_or(0);
    let far = per_pixel.iter().filter(|d| **d > 2).count() as f64 / per_pixel.len() as f64;
    (worst, far)
}

fn xdotool(x: &Xvfb, args: &[&str]) {
    let status = Command::new("xdotool")
        .args(args)
        .env("DISPLAY", &x.display)
        .status()
        .expect("xdotool runs");
    assert!(status.success(), "xdotool {args:?}");
}

/// Opens the viewer on `backend`, checks its still frame against `fray render`, flies forward
/// with W, saves with F12 and checks the save and the printed camera. `worst_allowed`: the
/// largest channel difference between the screen and `fray render` (0: the same bytes).
/// Gives the viewer's window the keyboard (Xvfb has no window manager to do it).
fn focus_viewer(x: &Xvfb) {
    let found = Command::new("xdotool")
        .args(["search", "--name", "fray view"])
        .env("DISPLAY", &x.display)
        .output()
        .expect("xdotool runs");
    let window = String::from_utf8_lossy(&found.stdout)
        .lines()
        .next()
        .expect("the viewer's window")
        .to_owned();
    xdotool(x, &["windowfocus", "--sync", &window]);
}

fn fly_and_save(backend: &str, worst_allowed: u8) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("view-{backend}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("xdg")).unwrap();
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let x = Xvfb::start();
    let mut viewer = Viewer::start(&x, &dir, &scene, backend);
    viewer.wait_for("first frame:");
    viewer.wait_for("still frame:");
    // The frame is drawn right after its line is printed.
    std::thread::sleep(Duration::from_millis(500));
    let first = screenshot(&x);
    let reference = render(&dir, &scene, backend, "reference.png");
    let (worst, far) = difference(&first, &reference);
    assert!(
        worst <= worst_allowed,
        "the first still frame on the screen is {worst} code values from fray render's"
    );
    assert_eq!(far, 0.0);

    // Fly forward, the window given the keyboard.
    focus_viewer(&x);
    xdotool(&x, &["mousemove", "160", "120"]);
    // Look left a little with the right button held: the view turns.
    xdotool(&x, &["mousedown", "3"]);
    for _ in 0..4 {
        xdotool(&x, &["mousemove_relative", "--", "-10", "0"]);
        std::thread::sleep(Duration::from_millis(50));
    }
    xdotool(&x, &["mouseup", "3"]);
    viewer.wait_for("still frame:");
    std::thread::sleep(Duration::from_millis(500));
    let turned = screenshot(&x);
    let (worst, _) = difference(&turned, &first);
    assert!(worst > 16, "the view did not turn (right drag)");
    xdotool(&x, &["keydown", "w"]);
    std::thread::sleep(Duration::from_millis(800));
    xdotool(&x, &["keyup", "w"]);
    viewer.wait_for("still frame:");
    std::thread::sleep(Duration::from_millis(500));
    let moved = screenshot(&x);
    let (worst, _) = difference(&moved, &turned);
    assert!(worst > 16, "the view did not move (W)");
    xdotool(&x, &["key", "F12"]);
    let saved_line = viewer.wait_for("saved ");
    let camera = viewer.wait_for("camera: Pinhole(");
    let status = viewer.child.wait().expect("the viewer exits after saving");
    assert!(status.success(), "{saved_line}");

    // The saved frame is `fray render`'s for the printed camera, byte for byte, and what the
    // screen showed.
    let saved = png(&dir.join("saved.png"));
    let original_camera = SCENE
        .lines()
        .find(|l| l.trim_start().starts_with("camera:"))
        .unwrap();
    let moved_scene = dir.join("moved.ron");
    std::fs::write(
        &moved_scene,
        SCENE.replace(original_camera, &format!("  {camera},")),
    )
    .unwrap();
    let check = Command::new(FRAY)
        .arg("check")
        .arg(&moved_scene)
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "the printed camera is valid: {camera}"
    );
    let again = render(&dir, &moved_scene, backend, "moved.png");
    assert!(
        saved == again,
        "the save is fray render's bytes for {camera}"
    );
    let (worst, far) = difference(&moved, &again);
    assert!(
        worst <= worst_allowed && far == 0.0,
        "the moved still frame on the screen is {worst} code values from fray render's"
    );
    let (worst, _) = difference(&saved, &reference);
    assert!(worst > 16, "the save shows the moved camera");
}

/// The probed views and playback: `--look steps` puts on the screen the heat map
/// `fray_view::probe` makes for the same camera, texel for texel; space pauses the playing
/// animation of an animated scene, and the frames shown while it played moved.
fn probe_and_play() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("view-probe");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("xdg")).unwrap();
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let x = Xvfb::start();
    let mut viewer = Viewer::start_with(&x, &dir, &scene, "cpu", &["--look", "steps"]);
    let line = viewer.wait_for("still frame:");
    assert!(line.contains("search steps per pixel"), "{line}");
    std::thread::sleep(Duration::from_millis(500));
    let screen = screenshot(&x);
    let mut resolved = fray_scene::parse(SCENE, "scene.ron").unwrap();
    (resolved.width, resolved.height) = SIZE;
    let probed = fray_view::probe(fray_view::ProbeView::Steps, &resolved, true, Some(2)).unwrap();
    let expected: Vec<[u8; 3]> = probed
        .rgba
        .chunks_exact(4)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    assert!(
        screen == expected,
        "the heat map on the screen is not the probe's"
    );
    drop(viewer);

    // The animated heights of data/scenes/terrain_waves.ron, playing from the start.
    let waves = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes/terrain_waves.ron");
    let mut viewer = Viewer::start_with(&x, &dir, &waves, "cpu", &["--play"]);
    viewer.wait_for("first frame:");
    std::thread::sleep(Duration::from_millis(1500));
    let before = screenshot(&x);
    std::thread::sleep(Duration::from_millis(1500));
    let later = screenshot(&x);
    let (worst, _) = difference(&before, &later);
    assert!(worst > 16, "the playing animation did not move the picture");
    focus_viewer(&x);
    xdotool(&x, &["key", "space"]);
    let paused = viewer.wait_for("paused at ");
    let t: f64 = paused
        .trim_start_matches("paused at ")
        .trim_end_matches(" s")
        .parse()
        .unwrap_or_else(|_| panic!("{paused}"));
    assert!(t > 0.0, "{paused}");
}

fn main() {
    let args = libtest_mimic::Arguments::from_args();
    let required = std::env::var("FRAY_REQUIRE_GPU").is_ok_and(|v| v == "1");
    let why = missing();
    if let Some(why) = &why {
        if required {
            panic!("FRAY_REQUIRE_GPU=1 but the viewer cannot be tested: {why}");
        }
        eprintln!("viewer tests ignored: {why}");
    }
    let trial = |name: &str, test: fn()| {
        libtest_mimic::Trial::test(name, move || {
            test();
            Ok(())
        })
        .with_ignored_flag(why.is_some())
    };
    let trials = vec![
        // The CPU's still frame is drawn from its PNG bytes, texel for texel.
        trial(
            "the_cpu_viewer_shows_flies_and_saves_what_fray_render_makes",
            || fly_and_save("cpu", 0),
        ),
        // The GPU's display texture is its tone map on the device (one code value from the
        // host's: `fray-gpu`'s display test), drawn with no readback.
        trial(
            "the_gpu_viewer_shows_flies_and_saves_what_fray_render_makes",
            || fly_and_save("gpu", 1),
        ),
        trial(
            "the_viewer_probes_steps_and_plays_and_pauses_an_animation",
            probe_and_play,
        ),
    ];
    libtest_mimic::run(&args, trials).exit()
}
