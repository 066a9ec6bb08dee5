//! A linear-light image, its 8-bit sRGB PNG encoding and its linear
//! OpenEXR one (`exr.rs`).

use crate::color::{Rgb, Tone, to_srgb8_toned};
use crate::output::{WriteError, write_with};
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first, linear RGB.
    pub pixels: Vec<Rgb>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Image {
            width,
            height,
            pixels: vec![Rgb::ZERO; width as usize * height as usize],
        }
    }

    pub fn get(&self, x: u32, y: u32) -> Rgb {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Interleaved 8-bit sRGB, 3 bytes a pixel.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.to_srgb8_toned(Tone::default())
    }

    /// [`Self::to_srgb8`] after `tone` (exposure and tone curve).
    pub fn to_srgb8_toned(&self, tone: Tone) -> Vec<u8> {
        self.pixels.iter().flat_map(|&c| to_srgb8_toned(c, tone)).collect()
    }

    /// Writes an 8-bit sRGB PNG atomically ([`crate::output`]): a failed
    /// write never leaves half a picture, a temporary file, or anything but
    /// a regular file replaced. The error names the path.
    pub fn write_png(&self, path: &Path) -> Result<(), WriteError> {
        self.write_png_toned(path, Tone::default())
    }

    /// [`Self::write_png`] after `tone`.
    pub fn write_png_toned(&self, path: &Path, tone: Tone) -> Result<(), WriteError> {
        write_with(path, |out| {
            let mut enc = png::Encoder::new(out, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            let mut w = enc.write_header().map_err(std::io::Error::other)?;
            w.write_image_data(&self.to_srgb8_toned(tone))
                .map_err(std::io::Error::other)?;
            w.finish().map_err(std::io::Error::other)
        })
    }

    /// Writes a linear RGB OpenEXR file atomically ([`crate::output`]): each
    /// channel the `f32` nearest the pixel's radiance, unclamped.
    pub fn write_exr(&self, path: &Path) -> Result<(), WriteError> {
        crate::output::write_file(path, &super::exr::encode(self.width, self.height, &self.pixels))
    }

    /// Writes the image in `format`: a PNG after `tone`, an EXR linear
    /// (the radiance itself, whatever the tone).
    pub fn write_as(&self, path: &Path, format: ImageFormat, tone: Tone) -> Result<(), WriteError> {
        match format {
            ImageFormat::Png => self.write_png_toned(path, tone),
            ImageFormat::Exr => self.write_exr(path),
        }
    }

    /// Reads an 8-bit RGB or RGBA PNG back into linear light.
    pub fn read_png(path: &Path) -> std::io::Result<Image> {
        let dec = png::Decoder::new(std::io::BufReader::new(crate::files::open_regular(path)?));
        let mut reader = dec.read_info().map_err(std::io::Error::other)?;
        let size = reader
            .output_buffer_size()
            .ok_or_else(|| std::io::Error::other("PNG too large"))?;
        let mut buf = vec![0; size];
        let info = reader.next_frame(&mut buf).map_err(std::io::Error::other)?;
        let channels = match info.color_type {
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            other => return Err(std::io::Error::other(format!("unsupported PNG colour type {other:?}"))),
        };
        if info.bit_depth != png::BitDepth::Eight {
            return Err(std::io::Error::other("only 8-bit PNGs are supported"));
        }
        let mut img = Image::new(info.width, info.height);
        for (i, px) in img.pixels.iter_mut().enumerate() {
            let b = &buf[i * channels..i * channels + 3];
            let f = |v: u8| crate::color::srgb_to_linear(v as f64 / 255.0);
            *px = Rgb::new(f(b[0]), f(b[1]), f(b[2]));
        }
        Ok(img)
    }
}

/// The formats an image is written in, told by the file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit sRGB after the tone, clamped to [0, 1] ([`Image::write_png`]).
    Png,
    /// Linear 32-bit float, unclamped ([`Image::write_exr`]).
    Exr,
}

impl ImageFormat {
    /// The format for `path` by its extension (`.png` or `.exr`, any case),
    /// or a one-line reason naming the path.
    pub fn of(path: &Path) -> Result<ImageFormat, String> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("exr") => Ok(ImageFormat::Exr),
            _ => Err(format!(
                "{}: unknown image extension (use .png for 8-bit sRGB or .exr for linear float)",
                path.display()
            )),
        }
    }
}
