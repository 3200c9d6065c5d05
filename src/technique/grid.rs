//! Grids sized to the penumbrae they hold (issue 20): a centred penumbra is smooth across its
//! whole width, so where every caster's is many texels wide a coarser grid resolves it as well,
//! and the passes that draw and clear the grid cost a fraction. The smoothie's map and buffer
//! and the plateau's textures are halved so, each from its own estimate of the narrowest
//! penumbra.

use super::knobs::Knob;

/// The knob both techniques take, each with its own help and measurements.
pub const PENUMBRA_TEXELS: Knob = Knob {
    name: "penumbra_texels",
    default: 10.0,
    min: 0.0,
    max: 1024.0,
    integer: false,
    choices: &[],
    help: "halve the grids (at most twice) while the narrowest penumbra spans this many texels; 0: off",
};

/// The most [`halvings`] take off a grid's size, and the least size they leave.
pub const MAX_HALVINGS: u32 = 2;
pub const MIN_HALVED_SIZE: u32 = 128;
/// How many times the texels asked for a frame's narrowest penumbra must span to take a
/// coarser grid than the frame before ([`halvings`]).
pub const HALVING_MARGIN: f32 = 1.25;

/// How many times a grid of `size` texels is halved: while the narrowest penumbra, `narrowest`
/// texels of it wide, still spans `texels` texels of the halved grid, at most [`MAX_HALVINGS`]
/// times and never below [`MIN_HALVED_SIZE`]; never with `texels` 0.
///
/// A switch of grids moves V where the hard edge crosses texels (the smoothie: by up to 0.13 at
/// a few pixels, sphere and contact, 3 and 73 of 262144 pixels by more than 0.02, a change a
/// moving caster would show as a flicker), so after the `previous` frame's count a coarser grid
/// needs [`HALVING_MARGIN`] times the texels, and the count it had is kept while it still fits.
pub fn halvings(narrowest: f32, size: u32, texels: f32, previous: Option<u32>) -> u32 {
    if texels <= 0.0 || !narrowest.is_finite() {
        return 0;
    }
    let fits = |h: u32, margin: f32| narrowest / (1u32 << h) as f32 >= texels * margin && size >> h >= MIN_HALVED_SIZE;
    let most = |up_to: u32, margin: f32| (1..=up_to).take_while(|&h| fits(h, margin)).last().unwrap_or(0);
    match previous {
        None => most(MAX_HALVINGS, 1.0),
        Some(previous) => most(MAX_HALVINGS, HALVING_MARGIN).max(most(previous.min(MAX_HALVINGS), 1.0)),
    }
}

/// A technique's last [`halvings`], with the texels asked for and the finest size they came
/// from: the next frame keeps the count within its margin only if those are the same.
#[derive(Clone, Copy, Debug, Default)]
pub struct Halving {
    last: Option<(f32, u32, u32)>,
}

impl Halving {
    /// This frame's halvings of a grid of `finest` texels whose narrowest penumbra is
    /// `narrowest` of them wide, for `texels` (0: none).
    pub fn next(&mut self, narrowest: f32, finest: u32, texels: f32) -> u32 {
        let previous = self.last.filter(|&(t, f, _)| (t, f) == (texels, finest)).map(|(_, _, h)| h);
        let h = halvings(narrowest, finest, texels, previous);
        self.last = Some((texels, finest, h));
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Halved, the narrowest penumbra still spans `texels`; halved once more it would not
        /// (after a frame with fewer halvings: not by the margin), or the grid would pass its
        /// limits; fewer than the frame before only where that frame's no longer fit.
        #[test]
        fn grids_halve_while_the_narrowest_penumbra_spans_enough_texels(
            narrowest in 0.0f32..2000.0,
            size_log in 4u32..14,
            texels in 0.0f32..64.0,
            previous in proptest::option::of(0u32..4),
        ) {
            let size = 1 << size_log;
            let h = halvings(narrowest, size, texels, previous);
            let fits = |h: u32, margin: f32| narrowest / (1u32 << h) as f32 >= texels * margin && size >> h >= MIN_HALVED_SIZE;
            proptest::prop_assert!(h <= MAX_HALVINGS);
            proptest::prop_assert!(texels > 0.0 || h == 0);
            proptest::prop_assert!(h == 0 || fits(h, 1.0), "{h} halvings do not fit");
            if texels > 0.0 {
                // Up to the frame before's count no margin is needed; beyond it, the margin.
                let margin = if previous.is_none_or(|p| h < p) { 1.0 } else { HALVING_MARGIN };
                proptest::prop_assert!(h == MAX_HALVINGS || !fits(h + 1, margin), "{h} halvings after {previous:?}, one more would do");
                if let Some(p) = previous.filter(|&p| p < h) {
                    proptest::prop_assert!(fits(h, HALVING_MARGIN), "{h} halvings after {p} without the margin");
                }
            }
        }
    }

    /// A frame keeps the last one's halvings only while asked for the same texels of the same
    /// grid.
    #[test]
    fn the_margin_holds_only_for_the_same_knobs() {
        let mut halving = Halving::default();
        // 50 texels wide: 10 fit twice halved (12.5), so the first frame takes two.
        assert_eq!(halving.next(50.0, 1024, 10.0), 2);
        // At 45 two halvings leave 11.25, under the margin's 12.5, but the last frame's count stands.
        assert_eq!(halving.next(45.0, 1024, 10.0), 2);
        // Asked for other texels, or of another grid, the margin applies afresh.
        assert_eq!(Halving::default().next(45.0, 1024, 10.0), 2);
        let mut from_one = Halving::default();
        assert_eq!(from_one.next(30.0, 1024, 10.0), 1);
        assert_eq!(from_one.next(45.0, 1024, 10.0), 1, "one more halving needs the margin");
        assert_eq!(from_one.next(45.0, 2048, 10.0), 2, "another grid: no last count");
    }
}
