//! Camera images in a recording: Foxglove's well-known `foxglove.CompressedImage` schema, a
//! JPEG per message, base64 in the JSON encoding (its `data` is bytes), so that Foxglove and
//! Lichtblick show the robots' cameras and the web monitor shows the selected robot's.

use base64::Engine as _;
use mrt_core::Time;
use mrt_msgs::Image;
use serde::{Deserialize, Serialize};

/// The JPEG quality of recorded camera images (0 to 100): a 320 × 240 rendering takes 5 to
/// 7 KB.
pub const JPEG_QUALITY: u8 = 75;

/// A time as Foxglove's schemas write it.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
pub struct Timestamp {
    /// Whole seconds.
    pub sec: u32,
    /// Nanoseconds past `sec`.
    pub nsec: u32,
}

/// Foxglove's `foxglove.CompressedImage`: one compressed camera image.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[schemars(rename = "foxglove.CompressedImage")]
pub struct CompressedImage {
    /// When the image was taken.
    pub timestamp: Timestamp,
    /// The camera's frame of reference (`camera`, `up_camera`).
    pub frame_id: String,
    /// The image file's bytes, base64 (JSON has no bytes).
    #[schemars(extend("contentEncoding" = "base64"))]
    pub data: String,
    /// Its format: `jpeg`.
    pub format: String,
}

impl CompressedImage {
    /// `image` taken at `time` by the camera `frame_id`, as a JPEG; `None` when the image's
    /// size does not match its bytes or the encoder refuses it.
    pub fn jpeg(image: &Image, time: Time, frame_id: &str) -> Option<CompressedImage> {
        let rgb = image::RgbImage::from_raw(image.width, image.height, image.rgb.clone())?;
        let mut jpeg = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, JPEG_QUALITY)
            .encode_image(&rgb)
            .ok()?;
        Some(CompressedImage {
            timestamp: Timestamp::of(time),
            frame_id: frame_id.to_string(),
            data: base64::engine::general_purpose::STANDARD.encode(jpeg),
            format: "jpeg".into(),
        })
    }

    /// The image file's bytes; `None` when `data` is not base64.
    pub fn bytes(&self) -> Option<Vec<u8>> {
        base64::engine::general_purpose::STANDARD.decode(&self.data).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image goes in as a JPEG and comes back as one of its size, the colours close.
    #[test]
    fn an_image_round_trips_through_jpeg() {
        let mut img = Image::new(32, 16);
        for (k, px) in img.rgb.chunks_mut(3).enumerate() {
            px.copy_from_slice(&[if k % 32 < 16 { 200 } else { 20 }, 120, 40]);
        }
        let c = CompressedImage::jpeg(&img, Time(2_500_000_000), "camera").unwrap();
        assert_eq!(c.timestamp, Timestamp { sec: 2, nsec: 500_000_000 });
        assert_eq!(c.format, "jpeg");
        let bytes = c.bytes().unwrap();
        assert_eq!(&bytes[..2], &[0xff, 0xd8], "a JPEG's start of image");
        let back = image::load_from_memory(&bytes).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (32, 16));
        let left = back.get_pixel(4, 8).0;
        assert!(left[0] > 150 && (left[1] as i32 - 120).abs() < 30, "{left:?}");
        let bad = Image { width: 5, height: 5, rgb: vec![0; 3] };
        assert!(CompressedImage::jpeg(&bad, Time(0), "camera").is_none());
        let schema = crate::catalogue::schema_of::<CompressedImage>();
        assert_eq!(schema["title"], "foxglove.CompressedImage", "{schema}");
    }
}
