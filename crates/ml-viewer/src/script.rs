//! Scripted sessions (`manylights view --script FILE`, CI): one command per line, `#` starts a
//! comment. The viewer runs them in order between frames.
//!
//! ```text
//! frames 10                # render 10 frames
//! technique deferred       # any --technique name
//! lights 1000              # light count (the scene's layout)
//! aa 4                     # anti-aliasing: off, 4, 8 or 16 (--aa)
//! environment sky          # load an environment: FILE, sky or none (--environment)
//! background environment   # colour or environment (--background)
//! resize 320 240           # ask the window for this inner size
//! minimize / restore       # ask the window system to iconify / restore the window
//! overlay off              # hide or show the egui overlay
//! screenshot out.png       # the rendered image, without overlay (what `render` writes)
//! window-shot ui.png       # the window as presented, overlay included
//! quit
//! ```

use std::path::PathBuf;

#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    Frames(u32),
    Antialiasing(String),
    Environment(String),
    Background(String),
    Technique(String),
    Lights(u64),
    Resize(u32, u32),
    Minimize,
    Restore,
    Overlay(bool),
    Screenshot(PathBuf),
    WindowShot(PathBuf),
    Quit,
}

/// Largest frame count and window side a script may ask for.
const MAX_FRAMES: u32 = 100_000;
const MAX_SIDE: u32 = 16_384;

/// The commands of a script's text; an error names the line.
pub fn parse(text: &str) -> Result<Vec<Command>, String> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let bad = |why: &str| format!("line {}: '{line}': {why}", i + 1);
        let number = |w: &str, max: u64| {
            w.parse::<u64>().ok().filter(|&n| n >= 1 && n <= max).ok_or_else(|| bad(&format!("expected a number from 1 to {max}")))
        };
        let command = match words[..] {
            ["frames", n] => Command::Frames(number(n, MAX_FRAMES as u64)? as u32),
            ["technique", name] => Command::Technique(name.to_owned()),
            ["lights", n] => Command::Lights(number(n, u64::MAX)?),
            ["aa", samples] => Command::Antialiasing(samples.to_owned()),
            ["environment", source] => Command::Environment(source.to_owned()),
            ["background", shown] => Command::Background(shown.to_owned()),
            ["resize", w, h] => Command::Resize(number(w, MAX_SIDE as u64)? as u32, number(h, MAX_SIDE as u64)? as u32),
            ["minimize"] => Command::Minimize,
            ["restore"] => Command::Restore,
            ["overlay", "on"] => Command::Overlay(true),
            ["overlay", "off"] => Command::Overlay(false),
            ["screenshot", path] => Command::Screenshot(PathBuf::from(path)),
            ["window-shot", path] => Command::WindowShot(PathBuf::from(path)),
            ["quit"] => Command::Quit,
            _ => return Err(bad("unknown command (frames N, technique NAME, lights N, aa N, environment SOURCE, background NAME, resize W H, minimize, restore, overlay on|off, screenshot PATH, window-shot PATH, quit)")),
        };
        out.push(command);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_parse_and_mistakes_name_their_line() {
        let script = "# a session\nframes 3\ntechnique deferred  # switch\nlights 1000\naa 4\nenvironment sky\nbackground environment\nresize 320 240\nminimize\nrestore\noverlay off\nscreenshot a.png\nwindow-shot b.png\nquit\n";
        assert_eq!(
            parse(script).unwrap(),
            vec![
                Command::Frames(3),
                Command::Technique("deferred".into()),
                Command::Lights(1000),
                Command::Antialiasing("4".into()),
                Command::Environment("sky".into()),
                Command::Background("environment".into()),
                Command::Resize(320, 240),
                Command::Minimize,
                Command::Restore,
                Command::Overlay(false),
                Command::Screenshot("a.png".into()),
                Command::WindowShot("b.png".into()),
                Command::Quit,
            ]
        );
        for (bad, line) in [("frames 0", 1), ("frames\n", 1), ("\nresize 10", 2), ("jump", 1), ("frames 1\nresize 99999 2", 2)] {
            let e = parse(bad).unwrap_err();
            assert!(e.starts_with(&format!("line {line}:")), "{bad:?}: {e}");
        }
    }
}
