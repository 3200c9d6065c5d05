//! A private X server for the window tests when no display is present: Xvfb on a free display
//! number, stopped when dropped.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The Xvfb this process started, if it started one.
pub struct Xvfb {
    child: Child,
    pub display: String,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        // Nothing to do if it already died: the test is over either way.
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Makes sure `DISPLAY` names an X server: the one already set, or an Xvfb started here on the
/// first free display number (its socket and lock file absent), which is returned so the
/// caller keeps it alive. Call before any thread starts: it sets `DISPLAY` for this process.
pub fn ensure_display() -> Option<Xvfb> {
    if std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty()) {
        return None;
    }
    for n in 90..190 {
        let socket = format!("/tmp/.X11-unix/X{n}");
        if Path::new(&socket).exists() || Path::new(&format!("/tmp/.X{n}-lock")).exists() {
            continue;
        }
        let display = format!(":{n}");
        let mut child = Command::new("Xvfb")
            .args([&display, "-screen", "0", "1024x768x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb (apt-get install xvfb; scripts/install-deps.sh installs it)");
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(10) {
            if child.try_wait().expect("Xvfb status").is_some() {
                break; // another process took this display first: try the next
            }
            if Path::new(&socket).exists() {
                // SAFETY: called before the test starts any thread.
                unsafe { std::env::set_var("DISPLAY", &display) };
                return Some(Xvfb { child, display });
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = child.kill();
        let _ = child.wait();
    }
    panic!("no free X display number in :90..:190 for Xvfb");
}
