//! PNG pictures of point sets: people look at a pattern before they trust
//! its numbers.

use std::path::Path;

use image::{ImageEncoder, Rgb, RgbImage, codecs::png::PngEncoder};

use crate::Error;
use crate::io::write_atomic;
use crate::points::{PointSet, PointSetError};

const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
const FRAME: Rgb<u8> = Rgb([190, 190, 190]);
const INK: [f64; 3] = [20.0, 40.0, 110.0];

/// Draws the projection of `set` onto `dims` (first → right, second → up)
/// in a `size`×`size` square, each point an anti-aliased dot whose radius
/// shrinks with N.
///
/// # Errors
/// [`PointSetError::Projection`] for bad `dims`.
pub fn render_points(
    set: &PointSet,
    dims: [usize; 2],
    size: u32,
) -> Result<RgbImage, PointSetError> {
    let proj = set.projected(&dims)?;
    let mut img = RgbImage::from_pixel(size, size, BACKGROUND);
    for i in 0..size {
        for (x, y) in [(i, 0), (i, size - 1), (0, i), (size - 1, i)] {
            img.put_pixel(x, y, FRAME);
        }
    }
    let s = size as f64;
    let radius = (0.2 * s / (proj.len().max(1) as f64).sqrt()).clamp(1.0, 6.0);
    for p in proj.points() {
        let (cx, cy) = (p[0] * s, (1.0 - p[1]) * s);
        let (x0, x1) = (
            (cx - radius - 1.0).floor().max(0.0) as u32,
            ((cx + radius + 1.0).ceil() as u32).min(size),
        );
        let (y0, y1) = (
            (cy - radius - 1.0).floor().max(0.0) as u32,
            ((cy + radius + 1.0).ceil() as u32).min(size),
        );
        for y in y0..y1 {
            for x in x0..x1 {
                let dist = ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt();
                let cover = (radius + 0.5 - dist).clamp(0.0, 1.0);
                if cover > 0.0 {
                    let px = img.get_pixel_mut(x, y);
                    for (c, ink) in px.0.iter_mut().zip(INK) {
                        *c = (*c as f64 * (1.0 - cover) + ink * cover).round() as u8;
                    }
                }
            }
        }
    }
    Ok(img)
}

/// Draws a 1D set (or dimension `dim` of any set) as a strip `size` wide
/// and `size`/8 high (at least 16): each point a vertical tick at its
/// coordinate, anti-aliased across its pixel column, so gaps and clumps
/// read along the line.
///
/// # Errors
/// [`PointSetError::Projection`] for a `dim` out of range.
pub fn render_points_1d(set: &PointSet, dim: usize, size: u32) -> Result<RgbImage, PointSetError> {
    let proj = set.projected(&[dim])?;
    let height = (size / 8).max(16);
    let mut img = RgbImage::from_pixel(size, height, BACKGROUND);
    for x in 0..size {
        img.put_pixel(x, 0, FRAME);
        img.put_pixel(x, height - 1, FRAME);
    }
    for y in 0..height {
        img.put_pixel(0, y, FRAME);
        img.put_pixel(size - 1, y, FRAME);
    }
    let margin = height / 4;
    for p in proj.points() {
        // The tick's centre at p·size: split its ink between the two
        // pixel columns it straddles.
        let centre = p[0] * size as f64 - 0.5;
        let left = centre.floor();
        for (column, cover) in [(left, 1.0 - (centre - left)), (left + 1.0, centre - left)] {
            if column < 0.0 || column >= size as f64 || cover <= 0.0 {
                continue;
            }
            for y in margin..height - margin {
                let px = img.get_pixel_mut(column as u32, y);
                for (c, ink) in px.0.iter_mut().zip(INK) {
                    *c = (*c as f64 * (1.0 - cover) + ink * cover).round() as u8;
                }
            }
        }
    }
    Ok(img)
}

/// Writes `img` to `path` as PNG, atomically.
///
/// # Errors
/// [`Error::Write`] naming `path`.
pub fn save_png(img: &RgbImage, path: &Path) -> Result<(), Error> {
    write_atomic(path, |w| {
        PngEncoder::new(w)
            .write_image(
                img.as_raw(),
                img.width(),
                img.height(),
                image::ExtendedColorType::Rgb8,
            )
            .map_err(std::io::Error::other)
    })
    .map_err(Error::from)
}
