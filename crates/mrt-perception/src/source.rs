//! Where camera images come from: one trait for every camera driver, and a
//! source that plays a directory of image files, so that the vision µAgent runs on real
//! images the same way it runs on the simulator's.
//!
//! - [`ImageSource`]: the driver trait. The simulator's renderer is one implementation (in
//!   `mrt-sim`, behind the robot's `Devices`); [`ImageSequence`] another; a USB camera a third.
//! - [`ImageSequence`]: the PNG or JPEG files of a directory in name order (or one file),
//!   optionally looping, each checked to be the camera's size.
//! - [`load_image`]: one file, decoded with the `image` crate under size limits, so that a
//!   hostile file gives an error and never a huge allocation.
//!
//! ```no_run
//! use mrt_perception::source::{ImageSequence, ImageSource};
//! let mut frames = ImageSequence::open("recordings/match1".as_ref())?.looping(false);
//! while let Some(image) = frames.grab()? {
//!     println!("{} × {}", image.width, image.height);
//! }
//! # Ok::<(), mrt_perception::source::SourceError>(())
//! ```

use crate::camera::MAX_SIDE;
use mrt_msgs::Image;
use std::path::{Path, PathBuf};

/// What can go wrong when reading images.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SourceError {
    /// The file or directory cannot be read.
    #[error("{path}: {reason}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The operating system's words.
        reason: String,
    },
    /// The file is not an image the decoder can read (or breaks the size limits).
    #[error("{path}: not a readable PNG or JPEG image: {reason}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// The decoder's words.
        reason: String,
    },
    /// A directory holds no PNG or JPEG file.
    #[error("{path}: no .png, .jpg or .jpeg files")]
    Empty {
        /// The directory.
        path: PathBuf,
    },
    /// An image is not the size the source was opened with (the camera's).
    #[error("{path}: the image is {got:?} pixels, expected {expected:?} (the camera's size)")]
    Size {
        /// The file.
        path: PathBuf,
        /// Columns and rows expected.
        expected: (u32, u32),
        /// Columns and rows of the image.
        got: (u32, u32),
    },
    /// The device is missing or refused (a camera driver's own words).
    #[error("{device}: {reason}")]
    Device {
        /// The device, e.g. `/dev/video0`.
        device: String,
        /// What went wrong.
        reason: String,
    },
}

/// A camera driver: hands out the next image (ISocRob-2000 report §3.2.1: the vision µAgent's input;
/// MRT manual ch. 12: the robots' cameras). `Ok(None)` means the source has ended (a file
/// sequence that does not loop); a live camera never ends.
pub trait ImageSource: Send {
    /// The next image.
    fn grab(&mut self) -> Result<Option<Image>, SourceError>;
    /// What the source reads from, for logs and errors.
    fn describe(&self) -> String;
}

/// Decodes one PNG or JPEG file (the format is read from the content, not the name) into an
/// RGB image, with at most [`MAX_SIDE`] pixels a side (the largest image a camera file and the
/// vision accept; a file claiming more is refused before its pixels are allocated).
pub fn load_image(path: &Path) -> Result<Image, SourceError> {
    let io = |e: std::io::Error| SourceError::Io { path: path.to_owned(), reason: e.to_string() };
    let decode =
        |e: image::ImageError| SourceError::Decode { path: path.to_owned(), reason: e.to_string() };
    let mut reader =
        image::ImageReader::open(path).map_err(io)?.with_guessed_format().map_err(io)?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_SIDE);
    limits.max_image_height = Some(MAX_SIDE);
    reader.limits(limits);
    let rgb = reader.decode().map_err(decode)?.to_rgb8();
    let (width, height) = rgb.dimensions();
    Ok(Image { width, height, rgb: rgb.into_raw() })
}

/// Whether a file name has an image extension this source plays.
fn is_image(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| matches!(e.to_ascii_lowercase().as_str(), "png" | "jpg" | "jpeg"))
}

/// The image files of a directory (in name order) or one file, played as a camera (module doc).
#[derive(Clone, Debug)]
pub struct ImageSequence {
    origin: PathBuf,
    files: Vec<PathBuf>,
    next: usize,
    looping: bool,
    size: Option<(u32, u32)>,
}

impl ImageSequence {
    /// The images of `path`: a directory's `.png`, `.jpg` and `.jpeg` files sorted by name
    /// (other files are skipped), or the one file `path` names. Plays once; see
    /// [`ImageSequence::looping`].
    pub fn open(path: &Path) -> Result<ImageSequence, SourceError> {
        let io =
            |e: std::io::Error| SourceError::Io { path: path.to_owned(), reason: e.to_string() };
        let files = if std::fs::metadata(path).map_err(io)?.is_dir() {
            let mut files = Vec::new();
            for entry in std::fs::read_dir(path).map_err(io)? {
                let p = entry.map_err(io)?.path();
                if is_image(&p) && p.is_file() {
                    files.push(p);
                }
            }
            files.sort();
            if files.is_empty() {
                return Err(SourceError::Empty { path: path.to_owned() });
            }
            files
        } else {
            vec![path.to_owned()]
        };
        Ok(ImageSequence { origin: path.to_owned(), files, next: 0, looping: false, size: None })
    }

    /// Starts again at the first image after the last (a recorded scene as an endless camera).
    pub fn looping(mut self, looping: bool) -> Self {
        self.looping = looping;
        self
    }

    /// Every image must be `width × height` (the camera file's size); by default the first
    /// image's size is required of the rest.
    pub fn expect_size(mut self, width: u32, height: u32) -> Self {
        self.size = Some((width, height));
        self
    }

    /// The files, in the order they are played.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }
}

impl ImageSource for ImageSequence {
    fn grab(&mut self) -> Result<Option<Image>, SourceError> {
        if self.next >= self.files.len() {
            if !self.looping {
                return Ok(None);
            }
            self.next = 0;
        }
        let path = &self.files[self.next];
        self.next += 1;
        let image = load_image(path)?;
        let got = (image.width, image.height);
        match self.size {
            Some(expected) if expected != got => {
                Err(SourceError::Size { path: path.clone(), expected, got })
            }
            Some(_) => Ok(Some(image)),
            None => {
                self.size = Some(got);
                Ok(Some(image))
            }
        }
    }

    fn describe(&self) -> String {
        format!("{} ({} images)", self.origin.display(), self.files.len())
    }
}
