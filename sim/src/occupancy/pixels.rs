//! From an image's pixel to a cell, as map_server reads it.
//!
//! The rules are those of ROS 2's map_server (`nav2_map_server/src/map_io.cpp`,
//! `loadMapFromFile`), with a pixel's value scaled by its image's maximum (255 for 8-bit, 65535
//! for 16-bit, a PGM's `maxval`):
//!
//! * the shade is the mean of the pixel's channels over the maximum; in `trinary` mode the alpha
//!   channel is averaged in with the colours, in `scale` and `raw` modes it is not (so in
//!   `trinary` mode an opaque black pixel of a gray-and-alpha image is `p = 0.5`, unknown with
//!   the usual thresholds: map_server's own rule, kept so a map reads here as it does there);
//! * the occupancy is `p = 1 - shade` (`p = shade` when `negate`);
//! * `trinary` and `scale`: `p > occupied_thresh` is occupied, `p < free_thresh` free, anything
//!   between unknown (map_server's `scale` mode gives the in-between cells a cost; a ray passes
//!   them here, as it passes unknown ones). In `scale` mode a pixel that is not fully opaque is
//!   unknown;
//! * `raw`: the shade times 255, rounded, is the occupancy in percent (negate is not applied);
//!   over 100 is unknown, and the percent is held to the thresholds as `p` is.
//!
//! ROS 1's map_server differs in two corners: in `scale` mode only a fully transparent pixel is
//! unknown, and in `raw` mode it applies `negate`.

use super::Cell;

/// How map_server reads a pixel's value (the YAML's `mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Mode {
    Trinary,
    Scale,
    Raw,
}

/// The YAML's reading of pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Rules {
    pub mode: Mode,
    pub negate: bool,
    pub occupied_thresh: f64,
    pub free_thresh: f64,
}

/// An image row's layout: samples per pixel, whether the last is alpha, the largest value.
#[derive(Clone, Copy, Debug)]
pub(super) struct Layout {
    pub channels: usize,
    pub alpha: bool,
    pub max: u16,
}

impl Rules {
    /// The cells of one image row, `samples` holding `layout.channels` values per pixel.
    pub fn classify(&self, samples: &[u16], layout: Layout, out: &mut [Cell]) {
        let max = f64::from(layout.max.max(1));
        let colours = if layout.alpha {
            layout.channels - 1
        } else {
            layout.channels
        };
        let averaged = if self.mode == Mode::Trinary {
            layout.channels
        } else {
            colours
        };
        for (pixel, cell) in samples.chunks_exact(layout.channels).zip(out) {
            let sum: u32 = pixel.iter().take(averaged).map(|&v| u32::from(v)).sum();
            let shade = f64::from(sum) / averaged as f64 / max;
            let opaque = !layout.alpha || pixel.last() == Some(&layout.max);
            *cell = match self.mode {
                Mode::Trinary => self.threshold(if self.negate { shade } else { 1.0 - shade }),
                Mode::Scale if !opaque => Cell::Unknown,
                Mode::Scale => self.threshold(if self.negate { shade } else { 1.0 - shade }),
                Mode::Raw => {
                    let percent = (shade * 255.0).round();
                    if percent > 100.0 {
                        Cell::Unknown
                    } else {
                        self.threshold(percent / 100.0)
                    }
                }
            };
        }
    }

    fn threshold(&self, p: f64) -> Cell {
        if p > self.occupied_thresh {
            Cell::Occupied
        } else if p < self.free_thresh {
            Cell::Free
        } else {
            Cell::Unknown
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GRAY: Layout = Layout {
        channels: 1,
        alpha: false,
        max: 255,
    };

    fn rules(mode: Mode, negate: bool) -> Rules {
        Rules {
            mode,
            negate,
            occupied_thresh: 0.65,
            free_thresh: 0.196,
        }
    }

    fn cells(rules: Rules, samples: &[u16], layout: Layout) -> Vec<Cell> {
        let mut out = vec![Cell::Unknown; samples.len() / layout.channels];
        rules.classify(samples, layout, &mut out);
        out
    }

    #[test]
    fn map_savers_values_read_back_as_what_it_wrote() {
        use Cell::*;
        assert_eq!(
            cells(rules(Mode::Trinary, false), &[0, 254, 205], GRAY),
            [Occupied, Free, Unknown]
        );
        // Negated, p is the shade: 205 gives 0.804, occupied; 50 gives 0.196, unknown.
        assert_eq!(
            cells(rules(Mode::Trinary, true), &[0, 254, 205, 50], GRAY),
            [Free, Occupied, Occupied, Unknown]
        );
    }

    #[test]
    fn thresholds_are_strict_as_map_servers() {
        // p = (255 - v)/255: v = 89 gives p = 0.6510 > 0.65; v = 90 gives 0.6471.
        let r = rules(Mode::Trinary, false);
        assert_eq!(cells(r, &[89, 90], GRAY), [Cell::Occupied, Cell::Unknown]);
        // v = 206 gives p = 0.1922 < 0.196; v = 205 gives 0.19608.
        assert_eq!(cells(r, &[206, 205], GRAY), [Cell::Free, Cell::Unknown]);
    }

    #[test]
    fn trinary_averages_alpha_in_and_scale_makes_translucent_pixels_unknown() {
        let gray_alpha = Layout {
            channels: 2,
            alpha: true,
            max: 255,
        };
        // White but transparent: trinary averages (255 + 0)/2, p = 0.5, unknown; scale: unknown.
        // White and opaque: free in both.
        let samples = [255, 0, 255, 255];
        assert_eq!(
            cells(rules(Mode::Trinary, false), &samples, gray_alpha),
            [Cell::Unknown, Cell::Free]
        );
        assert_eq!(
            cells(rules(Mode::Scale, false), &samples, gray_alpha),
            [Cell::Unknown, Cell::Free]
        );
        // Black, half transparent: trinary's mean 64, p = 0.75, occupied; scale: unknown.
        assert_eq!(
            cells(rules(Mode::Trinary, false), &[0, 128], gray_alpha),
            [Cell::Occupied]
        );
        assert_eq!(
            cells(rules(Mode::Scale, false), &[0, 128], gray_alpha),
            [Cell::Unknown]
        );
    }

    #[test]
    fn raw_values_are_percent_occupancy_and_ignore_negate() {
        use Cell::*;
        for negate in [false, true] {
            assert_eq!(
                cells(rules(Mode::Raw, negate), &[0, 100, 50, 101, 255], GRAY),
                [Free, Occupied, Unknown, Unknown, Unknown]
            );
        }
    }

    #[test]
    fn sixteen_bit_values_scale_by_their_maximum() {
        let wide = Layout {
            channels: 1,
            alpha: false,
            max: 65535,
        };
        assert_eq!(
            cells(rules(Mode::Trinary, false), &[0, 65535, 65535 / 2], wide),
            [Cell::Occupied, Cell::Free, Cell::Unknown]
        );
    }

    #[test]
    fn colour_channels_are_averaged() {
        let rgb = Layout {
            channels: 3,
            alpha: false,
            max: 255,
        };
        // Pure red: mean 85, p = 0.667 > 0.65.
        assert_eq!(
            cells(rules(Mode::Trinary, false), &[255, 0, 0], rgb),
            [Cell::Occupied]
        );
    }
}
