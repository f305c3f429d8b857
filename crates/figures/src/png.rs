//! PNG figures of model states (DLCA clusters, DLA clusters, animat snapshots), written with
//! the `png` crate and atomically.

use run_io::AtomicFile;
use std::path::Path;

/// Why a raster could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// Width or height is zero.
    #[error("image size {width}x{height}: both sides must be at least 1")]
    ZeroSize {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// The pixel buffer length does not match the size.
    #[error(
        "pixel buffer has {got} bytes, a {width}x{height} image with {channels} channel(s) needs {expected}"
    )]
    BufferSize {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Bytes per pixel.
        channels: usize,
        /// Bytes needed.
        expected: u64,
        /// Bytes given.
        got: usize,
    },
    /// The file could not be written.
    #[error("image I/O: {0}")]
    Io(#[from] std::io::Error),
    /// The PNG encoder failed.
    #[error("PNG encoding: {0}")]
    Png(#[from] png::EncodingError),
}

fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[u8],
    color: png::ColorType,
    channels: usize,
) -> Result<(), ImageError> {
    if width == 0 || height == 0 {
        return Err(ImageError::ZeroSize { width, height });
    }
    let expected = u64::from(width) * u64::from(height) * channels as u64;
    if pixels.len() as u64 != expected {
        return Err(ImageError::BufferSize {
            width,
            height,
            channels,
            expected,
            got: pixels.len(),
        });
    }
    let mut file = AtomicFile::create(path)?;
    {
        let mut enc = png::Encoder::new(&mut file, width, height);
        enc.set_color(color);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header()?;
        w.write_image_data(pixels)?;
        w.finish()?;
    }
    file.commit()?;
    Ok(())
}

/// Write an 8-bit grayscale PNG; `pixels` is row-major, top row first, one byte per pixel.
pub fn write_png_gray(
    path: impl AsRef<Path>,
    width: u32,
    height: u32,
    pixels: &[u8],
) -> Result<(), ImageError> {
    write_png(
        path.as_ref(),
        width,
        height,
        pixels,
        png::ColorType::Grayscale,
        1,
    )
}

/// Write an 8-bit RGB PNG; `pixels` is row-major, top row first, three bytes (R, G, B) per pixel.
pub fn write_png_rgb(
    path: impl AsRef<Path>,
    width: u32,
    height: u32,
    pixels: &[u8],
) -> Result<(), ImageError> {
    write_png(path.as_ref(), width, height, pixels, png::ColorType::Rgb, 3)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_back(path: &Path) -> (png::OutputInfo, Vec<u8>) {
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (info, buf)
    }

    #[test]
    fn round_trip_gray_and_rgb() {
        let dir = tempfile::tempdir().unwrap();
        let gray: Vec<u8> = (0..12).map(|i| i * 20).collect();
        write_png_gray(dir.path().join("g.png"), 4, 3, &gray).unwrap();
        let (info, data) = read_back(&dir.path().join("g.png"));
        assert_eq!(
            (info.width, info.height, info.color_type),
            (4, 3, png::ColorType::Grayscale)
        );
        assert_eq!(data, gray);

        let rgb: Vec<u8> = (0..2 * 5 * 3).map(|i| (i * 7) as u8).collect();
        write_png_rgb(dir.path().join("c.png"), 2, 5, &rgb).unwrap();
        let (info, data) = read_back(&dir.path().join("c.png"));
        assert_eq!(
            (info.width, info.height, info.color_type),
            (2, 5, png::ColorType::Rgb)
        );
        assert_eq!(data, rgb);
    }

    #[test]
    fn rejects_bad_sizes_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.png");
        assert!(matches!(
            write_png_rgb(&p, 2, 2, &[0; 11]),
            Err(ImageError::BufferSize { .. })
        ));
        assert!(matches!(
            write_png_gray(&p, 0, 2, &[]),
            Err(ImageError::ZeroSize { .. })
        ));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
