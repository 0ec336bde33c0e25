//! Grey images: linear radiance in PFM (Portable Float Map, the format
//! pbrt and most HDR tools read), tone-mapped PNG for looking at.

use std::io::{self, Write};
use std::path::Path;

use crate::Error;
use crate::io::write_atomic;
use crate::report::plot::{HeatMap, heatmap_png};

/// A grey image, rows from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct GreyImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width · height` values, row by row from the top.
    pub pixels: Vec<f64>,
}

impl GreyImage {
    /// Writes PFM: header `Pf`, `width height`, `-1` (little-endian), then
    /// f32 rows from the bottom up, as the format specifies.
    ///
    /// # Errors
    /// [`Error::Write`] naming `path`.
    pub fn write_pfm(&self, path: &Path) -> Result<(), Error> {
        write_atomic(path, |w| self.pfm(w)).map_err(Error::from)
    }

    /// Writes a NumPy `.npy` array of shape [height, width], float64, row 0
    /// at the top (`numpy.load` gives the image as it is shown).
    ///
    /// # Errors
    /// [`Error::Write`] naming `path`.
    pub fn write_npy(&self, path: &Path) -> Result<(), Error> {
        let shape = [self.height as u64, self.width as u64];
        write_atomic(path, |w| crate::io::npy::write_npy(w, &shape, &self.pixels))
            .map_err(Error::from)
    }

    fn pfm(&self, w: &mut dyn Write) -> io::Result<()> {
        write!(w, "Pf\n{} {}\n-1.0\n", self.width, self.height)?;
        for row in self.pixels.chunks_exact(self.width).rev() {
            for &v in row {
                w.write_all(&(v as f32).to_le_bytes())?;
            }
        }
        Ok(())
    }

    /// Reads a grey PFM written by [`Self::write_pfm`] or another tool
    /// (either byte order), or a colour one whose channels are equal at
    /// every pixel.
    ///
    /// # Errors
    /// A sentence naming what is wrong with the file.
    pub fn read_pfm(path: &Path) -> Result<GreyImage, String> {
        let limit = crate::memory::limit_mib().saturating_mul(1 << 20);
        let bytes = crate::io::read_bounded(path, limit, "a PFM image")
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let bad =
            |what: &str| format!("{}: not a PFM image of grey values: {what}", path.display());
        // Three whitespace-separated header tokens after `Pf`, then one
        // whitespace byte, then the data.
        let mut fields = Vec::new();
        let mut i = 0;
        while fields.len() < 4 {
            while i < bytes.len() && bytes[i].is_ascii_whitespace() {
                i += 1;
            }
            let start = i;
            while i < bytes.len() && !bytes[i].is_ascii_whitespace() {
                i += 1;
            }
            if start == i || i - start > 32 {
                return Err(bad("header cut short"));
            }
            fields.push(String::from_utf8_lossy(&bytes[start..i]).into_owned());
        }
        i += 1;
        // `PF` (colour) is read when its three channels agree at every
        // pixel: a grey image as other renderers write it.
        let channels = match fields[0].as_str() {
            "Pf" => 1,
            "PF" => 3,
            other => {
                return Err(bad(&format!(
                    "magic `{other}`, expected `Pf` (grey) or `PF` (colour)"
                )));
            }
        };
        let parse = |s: &str| {
            s.parse::<usize>()
                .ok()
                .filter(|&v| (1..=1 << 16).contains(&v))
        };
        let (Some(width), Some(height)) = (parse(&fields[1]), parse(&fields[2])) else {
            return Err(bad("size is not two integers from 1 to 65536"));
        };
        let scale: f64 = fields[3]
            .parse()
            .ok()
            .filter(|s: &f64| s.is_finite() && *s != 0.0)
            .ok_or_else(|| {
                bad("scale is not a nonzero number (its sign is the byte order: < 0 little-endian)")
            })?;
        let data = bytes.get(i..).unwrap_or_default();
        if data.len() != 4 * channels * width * height {
            return Err(bad(&format!(
                "{} data bytes where {width}×{height}×{channels} needs {}",
                data.len(),
                4 * channels * width * height
            )));
        }
        let value = |c: &[u8]| {
            let b = [c[0], c[1], c[2], c[3]];
            f64::from(if scale < 0.0 {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            })
        };
        let rows: Vec<Vec<f64>> = data
            .chunks_exact(4 * channels * width)
            .map(|row| row.chunks_exact(4).map(value).collect())
            .collect();
        // PFM rows run bottom to top.
        let rows = rows
            .into_iter()
            .enumerate()
            .map(|(r, row)| {
                if channels == 1 {
                    return Ok(row);
                }
                row.chunks_exact(3)
                    .enumerate()
                    .map(|(x, rgb)| {
                        // NaN channels are refused below, as a grey one is.
                        if rgb[0].to_bits() == rgb[1].to_bits()
                            && rgb[1].to_bits() == rgb[2].to_bits()
                        {
                            Ok(rgb[0])
                        } else {
                            Err(bad(&format!(
                                "a colour PFM whose channels differ at pixel ({x}, {}): {:?}; \
                                 the renderer's images are grey (give one channel, or equal ones)",
                                height - 1 - r,
                                // As stored (f32), not widened: 0.3, not
                                // 0.30000001192092896.
                                rgb.iter().map(|&v| v as f32).collect::<Vec<_>>()
                            )))
                        }
                    })
                    .collect()
            })
            .collect::<Result<Vec<Vec<f64>>, String>>()?;
        for (r, row) in rows.iter().enumerate() {
            if let Some(x) = row.iter().position(|v| !v.is_finite()) {
                return Err(bad(&format!(
                    "pixel ({x}, {}) is {}, not a finite value",
                    height - 1 - r,
                    row[x]
                )));
            }
        }
        Ok(GreyImage {
            width,
            height,
            pixels: rows.into_iter().rev().flatten().collect(),
        })
    }

    /// Writes an 8-bit PNG: radiance × `exposure`, clamped to [0, 1], sRGB
    /// encoded.
    ///
    /// # Errors
    /// [`Error::Write`] naming `path`.
    pub fn write_png(&self, exposure: f64, path: &Path) -> Result<(), Error> {
        let encode = |v: f64| {
            let l = (v * exposure).clamp(0.0, 1.0);
            let s = if l <= 0.003_130_8 {
                12.92 * l
            } else {
                1.055 * l.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0 + 0.5) as u8
        };
        let bytes: Vec<u8> = self.pixels.iter().flat_map(|&v| [encode(v); 3]).collect();
        let img = ::image::RgbImage::from_raw(self.width as u32, self.height as u32, bytes)
            .expect("buffer matches size");
        crate::report::png::save_png(&img, path)
    }
}

impl GreyImage {
    /// Writes a per-pixel variance image as a log10 heat map with a colour
    /// bar (zero variance grey). `colour_range` fixes the log10 range (to
    /// compare maps); by default it spans the 1st to 99.9th percentile, at
    /// most six decades.
    ///
    /// # Errors
    /// [`Error::Write`] naming `path`.
    pub fn write_variance_png(
        &self,
        title: &str,
        colour_range: Option<(f64, f64)>,
        path: &Path,
    ) -> Result<(), Error> {
        let logs: Vec<f64> = self
            .pixels
            .iter()
            .map(|&v| if v > 0.0 { v.log10() } else { f64::NAN })
            .collect();
        let all_zero = logs.iter().all(|v| v.is_nan());
        let (lo, hi) = colour_range.unwrap_or_else(|| {
            let mut finite: Vec<f64> = logs.iter().copied().filter(|v| v.is_finite()).collect();
            if finite.is_empty() {
                return (-1.0, 0.0);
            }
            finite.sort_by(f64::total_cmp);
            let at = |q: f64| finite[((q * finite.len() as f64) as usize).min(finite.len() - 1)];
            let hi = at(0.999);
            let lo = at(0.01).max(hi - 6.0);
            // Variances equal to a thousandth of a decade (a row of equal
            // pixels, differing by rounding) read as one value: the bar
            // spans a decade each side of it, not eleven equal ticks.
            if hi - lo < 1e-3 {
                let mid = 0.5 * (lo + hi);
                (mid - 1.0, mid + 1.0)
            } else {
                (lo, hi)
            }
        });
        // Every pixel grey: the bar's range maps nothing, and the title says
        // why.
        let title = if all_zero {
            format!("{title} (every pixel's variance is 0)")
        } else {
            title.to_string()
        };
        heatmap_png(
            &HeatMap {
                title,
                values: &logs,
                width: self.width,
                x_range: (0.0, self.width as f64),
                y_range: (self.height as f64, 0.0),
                x_label: "pixel x".into(),
                y_label: "pixel y (from the top)".into(),
                bar_label: "log10 variance (grey: 0)".into(),
                colour_range: (lo, hi),
            },
            path,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(bytes: &[u8]) -> Result<GreyImage, String> {
        let dir = std::env::temp_dir().join(format!("varspec-pfm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let file = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let path = dir.join(format!("{file}.pfm"));
        std::fs::write(&path, bytes).unwrap();
        let image = GreyImage::read_pfm(&path);
        std::fs::remove_file(&path).unwrap();
        image
    }

    fn pfm(scale: &str, values: [f32; 2]) -> Vec<u8> {
        let mut bytes = format!("Pf\n2 1\n{scale}\n").into_bytes();
        for v in values {
            bytes.extend(v.to_le_bytes());
        }
        bytes
    }

    #[test]
    fn a_written_image_reads_back() {
        let image = GreyImage {
            width: 2,
            height: 2,
            pixels: vec![0.25, 1.5, -2.0, 8.0],
        };
        let mut bytes = Vec::new();
        image.pfm(&mut bytes).unwrap();
        assert_eq!(read(&bytes).unwrap(), image);
    }

    /// A colour PFM (pbrt's, say) of a grey image reads as that image; one
    /// whose channels differ is refused at the pixel (two rows, so the
    /// pixel's y counts from the top as the renderer's do).
    #[test]
    fn a_colour_pfm_of_equal_channels_reads_as_grey() {
        let colour = |rgb: [[f32; 3]; 2]| {
            // Two rows of one pixel, written bottom row first.
            let mut bytes = b"PF\n1 2\n-1.0\n".to_vec();
            for v in rgb.iter().flatten() {
                bytes.extend(v.to_le_bytes());
            }
            bytes
        };
        let image = read(&colour([[0.25; 3], [1.5; 3]])).unwrap();
        assert_eq!(
            image,
            GreyImage {
                width: 1,
                height: 2,
                pixels: vec![1.5, 0.25],
            }
        );
        let e = read(&colour([[0.25, 0.25, 0.3], [1.5; 3]])).unwrap_err();
        assert!(
            e.contains("a colour PFM whose channels differ at pixel (0, 1): [0.25, 0.25, 0.3]"),
            "{e}"
        );
        let e = read(b"P6\n1 1\n-1.0\n\0\0\0\0").unwrap_err();
        assert!(
            e.contains("magic `P6`, expected `Pf` (grey) or `PF` (colour)"),
            "{e}"
        );
    }

    #[test]
    fn non_finite_pixels_and_a_zero_scale_are_refused() {
        let nan = read(&pfm("-1.0", [0.5, f32::NAN])).unwrap_err();
        assert!(
            nan.contains("pixel (1, 0) is NaN, not a finite value"),
            "{nan}"
        );
        let inf = read(&pfm("-1.0", [f32::INFINITY, 0.5])).unwrap_err();
        assert!(inf.contains("pixel (0, 0) is inf"), "{inf}");
        for scale in ["0", "0.0", "nan", "inf"] {
            let e = read(&pfm(scale, [0.5, 0.5])).unwrap_err();
            assert!(e.contains("scale is not a nonzero number"), "{scale}: {e}");
        }
    }
}
