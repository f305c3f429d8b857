//! Animations of runs: GIF files written frame by frame as a run goes (the `gif` crate of the
//! image-rs project), so a run keeps at most two frames in memory whatever its length. The
//! file is written atomically: it appears complete when [`Gif::finish`] returns, or not at
//! all.

use super::Raster;
use crate::{Error, Result};
use anyhow::Context;
use run_io::AtomicFile;
use std::path::{Path, PathBuf};

/// Largest side of an animation frame: GIF stores sizes in 16 bits.
pub const MAX_SIDE: u32 = u16::MAX as u32;

/// Hundredths of a second each frame is shown.
pub const FRAME_DELAY_CS: u16 = 10;
/// Hundredths of a second the last frame is shown before the animation repeats.
pub const LAST_FRAME_DELAY_CS: u16 = 200;

/// A GIF being written: frames are quantised to 256 colours (NeuQuant) and encoded as they
/// come; the last frame is held back so that it can be shown longer.
pub struct Gif {
    path: PathBuf,
    encoder: Option<gif::Encoder<std::io::BufWriter<AtomicFile>>>,
    size: (u32, u32),
    pending: Option<gif::Frame<'static>>,
    frames: u64,
}

impl std::fmt::Debug for Gif {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gif")
            .field("path", &self.path)
            .field("size", &self.size)
            .field("frames", &self.frames)
            .finish()
    }
}

impl Gif {
    /// Starts a GIF at `path` whose frames are all `width` x `height` pixels, repeating forever.
    pub fn create(path: &Path, width: u32, height: u32) -> Result<Self> {
        ensure!(
            (1..=MAX_SIDE).contains(&width) && (1..=MAX_SIDE).contains(&height),
            "an animation frame of {width}x{height} pixels: GIF sides are 1 to {MAX_SIDE}"
        );
        let file =
            AtomicFile::create(path).with_context(|| format!("creating {}", path.display()))?;
        let mut encoder = gif::Encoder::new(
            std::io::BufWriter::new(file),
            width as u16,
            height as u16,
            &[],
        )
        .with_context(|| format!("writing {}", path.display()))?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(Gif {
            path: path.to_path_buf(),
            encoder: Some(encoder),
            size: (width, height),
            pending: None,
            frames: 0,
        })
    }

    /// The size every frame must have.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Frames added so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Adds a frame (of the size given to [`Gif::create`]).
    pub fn push(&mut self, frame: &Raster) -> Result<()> {
        ensure!(
            (frame.width, frame.height) == self.size,
            "animation frame of {}x{} pixels, the animation's are {}x{}",
            frame.width,
            frame.height,
            self.size.0,
            self.size.1
        );
        // Speed 10 of 1 (best) to 30 (fastest): NeuQuant's default trade-off.
        let mut f =
            gif::Frame::from_rgb_speed(frame.width as u16, frame.height as u16, &frame.rgb, 10);
        f.delay = FRAME_DELAY_CS;
        if let Some(previous) = self.pending.replace(f) {
            self.write(&previous)?;
        }
        self.frames += 1;
        Ok(())
    }

    fn write(&mut self, frame: &gif::Frame<'_>) -> Result<()> {
        let encoder = self
            .encoder
            .as_mut()
            .context("animation already finished")?;
        encoder
            .write_frame(frame)
            .with_context(|| format!("writing {}", self.path.display()))
            .map_err(Error::from)
    }

    /// Writes the last frame (shown longer) and the file; returns the number of frames.
    pub fn finish(mut self) -> Result<u64> {
        ensure!(
            self.frames > 0,
            "an animation needs a frame: {}",
            self.path.display()
        );
        if let Some(mut last) = self.pending.take() {
            last.delay = LAST_FRAME_DELAY_CS;
            self.write(&last)?;
        }
        let encoder = self.encoder.take().context("animation already finished")?;
        let file = encoder
            .into_inner()
            .with_context(|| format!("writing {}", self.path.display()))?
            .into_inner()
            .map_err(|e| e.into_error())
            .with_context(|| format!("writing {}", self.path.display()))?;
        file.commit()
            .with_context(|| format!("writing {}", self.path.display()))?;
        Ok(self.frames)
    }
}

/// Reads a GIF back: its size and the number of frames (for tests and checks).
pub fn read_gif(path: &Path) -> Result<((u32, u32), u64)> {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let file = std::fs::File::open(path).with_context(|| format!("opening {}", path.display()))?;
    let mut decoder = options
        .read_info(std::io::BufReader::new(file))
        .with_context(|| format!("reading {}", path.display()))?;
    let size = (u32::from(decoder.width()), u32::from(decoder.height()));
    let mut frames = 0;
    while decoder
        .read_next_frame()
        .with_context(|| format!("reading {}", path.display()))?
        .is_some()
    {
        frames += 1;
    }
    Ok((size, frames))
}

/// Largest side in pixels of an animation frame (`--png-size` with `--animate`).
pub const ANIMATION_MAX_SIDE: u32 = 16384;

/// The checks every binary makes of its raster flags: `--animate-every` at least 1,
/// `--png-size` only with a raster to size (`stills` names the flag of the still figures:
/// `--png` or `--snapshot-every`, given or not as `still`), and at most
/// [`ANIMATION_MAX_SIDE`] with `--animate`.
pub fn check_figure_flags(
    png_size: Option<u32>,
    animate: bool,
    animate_every: Option<u64>,
    still: bool,
    stills: &str,
) -> Result<(), String> {
    if animate_every == Some(0) {
        return Err("--animate-every 0 is outside the accepted range 1..".into());
    }
    if png_size.is_some() && !still && !animate {
        return Err(format!(
            "--png-size sizes the figures of {stills} and --animate; give one"
        ));
    }
    if let Some(side) = png_size.filter(|&s| animate && s > ANIMATION_MAX_SIDE) {
        return Err(format!(
            "--png-size {side} with --animate: animation frames are at most {ANIMATION_MAX_SIDE} \
             pixels a side"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_written_and_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.gif");
        let mut gif = Gif::create(&path, 40, 30).unwrap();
        for i in 0..5u8 {
            let mut r = Raster::new(40, 30, [255, 255, 255]);
            r.put(u32::from(i), 3, [200, 0, 0]);
            gif.push(&r).unwrap();
        }
        assert!(gif.push(&Raster::new(41, 30, [0, 0, 0])).is_err());
        // Nothing is visible before the animation is finished.
        assert!(!path.exists());
        assert_eq!(gif.finish().unwrap(), 5);
        assert_eq!(read_gif(&path).unwrap(), ((40, 30), 5));
    }

    #[test]
    fn an_empty_animation_is_an_error_and_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.gif");
        let gif = Gif::create(&path, 4, 4).unwrap();
        assert!(gif.finish().is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        assert!(Gif::create(&path, 0, 4).is_err());
    }
}
