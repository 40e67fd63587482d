//! The image-sequence camera driver: order, looping, sizes, and hostile files.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use mrt_perception::source::{load_image, ImageSequence, ImageSource, SourceError};
use proptest::prelude::*;
use std::path::PathBuf;

/// A fresh directory under the system's temporary directory (removed by `Drop`).
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("mrt-source-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A `w × h` image whose first pixel's red channel is `mark`.
fn write_png(path: &std::path::Path, w: u32, h: u32, mark: u8) {
    let mut img = image::RgbImage::from_pixel(w, h, image::Rgb([0, 120, 0]));
    img.put_pixel(0, 0, image::Rgb([mark, 0, 0]));
    img.save(path).unwrap();
}

#[test]
fn a_directory_plays_its_images_in_name_order_then_ends_or_loops() {
    let dir = Scratch::new("order");
    // Written out of order, with a file that is not an image.
    write_png(&dir.0.join("frame_002.png"), 8, 6, 2);
    write_png(&dir.0.join("frame_001.png"), 8, 6, 1);
    image::RgbImage::from_pixel(8, 6, image::Rgb([3, 0, 0]))
        .save(dir.0.join("frame_003.jpg"))
        .unwrap();
    std::fs::write(dir.0.join("notes.txt"), "not an image").unwrap();

    let mut seq = ImageSequence::open(&dir.0).unwrap();
    assert_eq!(seq.files().len(), 3);
    assert!(seq.describe().contains("3 images"));
    let marks: Vec<u8> = std::iter::from_fn(|| seq.grab().unwrap()).map(|i| i.rgb[0]).collect();
    assert_eq!(marks.len(), 3);
    assert_eq!(&marks[..2], &[1, 2]);
    assert!(marks[2].abs_diff(3) <= 2, "JPEG keeps the red mark within its loss: {}", marks[2]);
    assert!(seq.grab().unwrap().is_none(), "a sequence that does not loop ends");

    let mut looping = ImageSequence::open(&dir.0).unwrap().looping(true);
    let marks: Vec<u8> = (0..7).map(|_| looping.grab().unwrap().unwrap().rgb[0]).collect();
    assert_eq!((marks[0], marks[3], marks[6]), (1, 1, 1));
}

#[test]
fn an_image_of_another_size_is_an_error_naming_the_file() {
    let dir = Scratch::new("size");
    write_png(&dir.0.join("a.png"), 8, 6, 1);
    write_png(&dir.0.join("b.png"), 6, 8, 2);
    let mut seq = ImageSequence::open(&dir.0).unwrap();
    assert!(seq.grab().unwrap().is_some());
    match seq.grab() {
        Err(e @ SourceError::Size { .. }) => {
            let text = e.to_string();
            assert!(text.contains("b.png") && text.contains("(6, 8)"), "{text}");
        }
        other => panic!("expected a size error, got {other:?}"),
    }
    // With the camera's size given, the first image is checked too.
    let mut seq = ImageSequence::open(&dir.0).unwrap().expect_size(320, 240);
    assert!(matches!(seq.grab(), Err(SourceError::Size { expected: (320, 240), .. })));
}

#[test]
fn a_missing_path_or_an_empty_directory_is_a_clear_error() {
    let dir = Scratch::new("empty");
    let e = ImageSequence::open(&dir.0).unwrap_err();
    assert!(matches!(e, SourceError::Empty { .. }), "{e}");
    let missing = dir.0.join("nowhere");
    let e = ImageSequence::open(&missing).unwrap_err();
    assert!(matches!(e, SourceError::Io { .. }) && e.to_string().contains("nowhere"), "{e}");
}

#[test]
fn a_file_claiming_a_giant_image_is_refused_before_its_pixels_are_allocated() {
    let dir = Scratch::new("giant");
    // A PNG header (signature and IHDR) claiming 100 000 × 100 000 pixels, and nothing else.
    let mut png = vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    png.extend_from_slice(&13u32.to_be_bytes());
    png.extend_from_slice(&ihdr);
    png.extend_from_slice(&crc32(&ihdr).to_be_bytes());
    let path = dir.0.join("giant.png");
    std::fs::write(&path, &png).unwrap();
    let e = load_image(&path).unwrap_err();
    assert!(matches!(e, SourceError::Decode { .. }) && e.to_string().contains("giant.png"), "{e}");
}

/// CRC-32 of PNG chunks (ISO 3309), bit by bit: small and only for this test's header.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xedb8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Random bytes, bare or behind a PNG or JPEG signature, never panic the loader.
    #[test]
    fn random_bytes_are_an_error_or_an_image(
        prefix in prop_oneof![
            Just(Vec::new()),
            Just(vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]),
            Just(vec![0xff, 0xd8, 0xff, 0xe0]),
        ],
        body in proptest::collection::vec(any::<u8>(), 0..600),
    ) {
        let dir = Scratch::new("fuzz");
        let path = dir.0.join("frame.png");
        let mut bytes = prefix;
        bytes.extend_from_slice(&body);
        std::fs::write(&path, &bytes).unwrap();
        match load_image(&path) {
            Ok(img) => prop_assert!(img.is_consistent()),
            Err(e) => prop_assert!(e.to_string().contains("frame.png")),
        }
    }
}
