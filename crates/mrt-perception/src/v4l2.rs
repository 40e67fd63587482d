//! A USB camera on Linux (Video4Linux2), as an [`ImageSource`]:
//! the robot's own camera for the vision µAgent (ISocRob's robots carried USB cameras, ISocRob-2000
//! report §2.2). Behind the `v4l2` cargo feature, on Linux only.
//!
//! The camera is asked for the camera file's size in RGB24, YUYV (4:2:2, the format nearly
//! every webcam offers) or Motion-JPEG, in that order of preference. YUYV is converted with
//! the ITU-R BT.601 equations; a JPEG frame is decoded under the same size limits as an image
//! file. A camera that offers none of the three, or another size than the camera file's, is
//! refused with the formats and size it offered. A missing device is an error that says so.
//!
//! Uses the `linuxvideo` crate (the kernel's V4L2 ioctls in Rust; no C headers or libclang
//! at build time, unlike `v4l`'s bindings).
//!
//! ```no_run
//! use mrt_perception::source::ImageSource;
//! use mrt_perception::v4l2::V4l2Camera;
//! let mut camera = V4l2Camera::open("/dev/video0".as_ref(), 320, 240)?;
//! let image = camera.grab()?.expect("a live camera never ends");
//! assert_eq!((image.width, image.height), (320, 240));
//! # Ok::<(), mrt_perception::source::SourceError>(())
//! ```

use crate::camera::MAX_SIDE;
use crate::source::{ImageSource, SourceError};
use linuxvideo::format::{PixFormat, PixelFormat};
use linuxvideo::stream::ReadStream;
use linuxvideo::{BufType, Device};
use mrt_msgs::Image;
use std::path::{Path, PathBuf};

/// The pixel formats asked for, in order of preference.
const PREFERRED: [PixelFormat; 3] = [PixelFormat::RGB3, PixelFormat::YUYV, PixelFormat::MJPG];

/// A V4L2 capture device streaming frames of one size (module doc).
pub struct V4l2Camera {
    device: PathBuf,
    stream: ReadStream,
    format: PixelFormat,
    width: u32,
    height: u32,
    /// Bytes from one row to the next in the device's buffers.
    stride: usize,
}

impl V4l2Camera {
    /// Opens `device` (e.g. `/dev/video0`) and starts streaming `width × height` frames.
    pub fn open(device: &Path, width: u32, height: u32) -> Result<V4l2Camera, SourceError> {
        let fail =
            |reason: String| SourceError::Device { device: device.display().to_string(), reason };
        if !device.exists() {
            return Err(fail(
                "no such device: is the camera plugged in? (`ls /dev/video*`)".into(),
            ));
        }
        let dev = Device::open(device)
            .map_err(|e| fail(format!("cannot open it as a V4L2 device: {e}")))?;
        let offered: Vec<PixelFormat> = dev
            .formats(BufType::VIDEO_CAPTURE)
            .filter_map(|f| f.ok().map(|f| f.pixel_format()))
            .collect();
        let format = PREFERRED
            .into_iter()
            .find(|f| offered.contains(f))
            .ok_or_else(|| fail(format!("offers {offered:?}; MRT reads RGB3, YUYV or MJPG")))?;
        let capture = dev
            .video_capture(PixFormat::new(width, height, format))
            .map_err(|e| fail(format!("refused {width}×{height} {format}: {e}")))?;
        let got = capture.format();
        if (got.width(), got.height()) != (width, height) {
            return Err(fail(format!(
                "offers {}×{} instead of the camera file's {width}×{height}",
                got.width(),
                got.height()
            )));
        }
        let stride = usize::try_from(got.bytes_per_line()).unwrap_or(0);
        let stream = capture.into_stream().map_err(|e| fail(format!("cannot stream: {e}")))?;
        Ok(V4l2Camera { device: device.to_owned(), stream, format, width, height, stride })
    }
}

impl ImageSource for V4l2Camera {
    fn grab(&mut self) -> Result<Option<Image>, SourceError> {
        let (format, width, height, stride) = (self.format, self.width, self.height, self.stride);
        let frame = self.stream.dequeue(|buf| Ok(to_rgb(&buf, format, width, height, stride)));
        let device = self.device.display().to_string();
        match frame {
            Ok(Ok(image)) => Ok(Some(image)),
            Ok(Err(reason)) => Err(SourceError::Device { device, reason }),
            Err(e) => Err(SourceError::Device { device, reason: format!("no frame: {e}") }),
        }
    }

    fn describe(&self) -> String {
        format!("{} ({}×{} {})", self.device.display(), self.width, self.height, self.format)
    }
}

/// One frame of the device's buffer as RGB (`stride`: bytes per row; 0 for compressed frames).
fn to_rgb(
    data: &[u8],
    format: PixelFormat,
    width: u32,
    height: u32,
    stride: usize,
) -> Result<Image, String> {
    let (w, h) = (width as usize, height as usize);
    let mut image = Image::new(width, height);
    if format == PixelFormat::MJPG {
        let mut reader =
            image::ImageReader::with_format(std::io::Cursor::new(data), image::ImageFormat::Jpeg);
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_SIDE);
        limits.max_image_height = Some(MAX_SIDE);
        reader.limits(limits);
        let rgb = reader.decode().map_err(|e| format!("a broken JPEG frame: {e}"))?.to_rgb8();
        if rgb.dimensions() != (width, height) {
            return Err(format!("a JPEG frame of {:?} pixels", rgb.dimensions()));
        }
        image.rgb = rgb.into_raw();
        return Ok(image);
    }
    let row_bytes = if format == PixelFormat::YUYV { 2 * w } else { 3 * w };
    let stride = stride.max(row_bytes);
    if h > 0 && data.len() < stride * (h - 1) + row_bytes {
        return Err(format!("a short frame: {} bytes for {width}×{height}", data.len()));
    }
    for (y, out) in image.rgb.chunks_exact_mut(3 * w.max(1)).take(h).enumerate() {
        let row = &data[y * stride..y * stride + row_bytes];
        if format == PixelFormat::YUYV {
            yuyv_row(row, out);
        } else {
            out.copy_from_slice(row);
        }
    }
    Ok(image)
}

/// One row of YUYV (Y0 U Y1 V for two pixels) as RGB, by ITU-R BT.601 (studio range:
/// Y 16–235, U and V 16–240 around 128).
fn yuyv_row(row: &[u8], out: &mut [u8]) {
    for (yuyv, rgb) in row.chunks_exact(4).zip(out.chunks_mut(6)) {
        let (u, v) = (f32::from(yuyv[1]) - 128.0, f32::from(yuyv[3]) - 128.0);
        for (k, px) in rgb.chunks_mut(3).enumerate() {
            let y = 1.164 * (f32::from(yuyv[2 * k]) - 16.0);
            let channel = |c: f32| c.round().clamp(0.0, 255.0) as u8;
            px[0] = channel(y + 1.596 * v);
            if let Some(g) = px.get_mut(1) {
                *g = channel(y - 0.392 * u - 0.813 * v);
            }
            if let Some(b) = px.get_mut(2) {
                *b = channel(y + 2.017 * u);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_device_says_so() {
        let e = V4l2Camera::open("/dev/video-mrt-none".as_ref(), 320, 240).err().unwrap();
        assert!(e.to_string().starts_with("/dev/video-mrt-none: no such device"), "{e}");
        let e = V4l2Camera::open("/dev/null".as_ref(), 320, 240).err().unwrap();
        assert!(e.to_string().contains("cannot open it as a V4L2 device"), "{e}");
    }

    #[test]
    fn yuyv_becomes_the_bt601_colours() {
        // Black and white (one pair of pixels shares its chroma), two reds, two blues
        // (BT.601 studio-range codes).
        let yuyv = [16, 128, 235, 128, 81, 90, 81, 240, 41, 240, 41, 110];
        let short = to_rgb(&yuyv, PixelFormat::YUYV, 2, 4, 4).unwrap_err();
        assert!(short.contains("short frame"), "four rows of 4 bytes: {short}");
        let image = to_rgb(&yuyv, PixelFormat::YUYV, 6, 1, 12).unwrap();
        assert_eq!(&image.rgb[..6], &[0, 0, 0, 255, 255, 255]);
        assert_eq!(&image.rgb[6..9], &[254, 0, 0], "R = 1.164·65 + 1.596·112 = 254.4");
        assert_eq!(&image.rgb[12..15], &[0, 0, 255], "B = 1.164·25 + 2.017·112");
    }

    #[test]
    fn rgb_rows_skip_the_padding_and_broken_jpeg_is_an_error() {
        let mut data = vec![0u8; 2 * 8];
        data[8..14].copy_from_slice(&[1, 2, 3, 4, 5, 6]);
        let image = to_rgb(&data, PixelFormat::RGB3, 2, 2, 8).unwrap();
        assert_eq!(image.rgb, [0, 0, 0, 0, 0, 0, 1, 2, 3, 4, 5, 6]);
        assert!(to_rgb(&[0xFF, 0xD8, 0], PixelFormat::MJPG, 2, 2, 0).is_err());
    }
}
