//! The falloff curve that turns a linear penumbra parameter into a gradient (Haines §3,
//! Chan & Durand §3.1), and where the penumbra lies: the knobs the plateau and the smoothie
//! share. The curves are linear, sine (Parker et al.), smoothstep (Parker's Bernstein
//! interpolant) and the exact visible fraction of a spherical light behind a straight edge (the
//! disk segment; the same half-plane test the ray tracer checks), computed where the resolves
//! need them (`glsl/common/falloff.glsl`), not read from the papers' 1D texture.

use super::knobs::Knob;

/// The knob choosing the curve. Linear is the default: it measured best against the reference
/// for both plateaus and smoothies (the outer-only penumbrae start at the hard edge, where the
/// true V is already ½, and the sine and smoothstep curves stay darker longer).
pub const FALLOFF: Knob = Knob::choice(
    "falloff",
    0.0,
    &["linear", "sine", "smoothstep", "disk"],
    "gradient: linear, sine (Haines 3), smoothstep (Parker), disk edge (exact for a straight edge)",
);

/// Where the penumbra lies (issue 20): 0, the papers' outer-only form, grown outward from the
/// hard shadow, whose whole area stays umbra (Haines §4, Chan & Durand §3); 1, centred on the
/// hard edge with the physical width, V = ½ on the edge and the umbra shrinking as the light
/// grows. A technique whose measured default differs declares `Knob { default: 1.0, ..PENUMBRA }`.
pub const PENUMBRA: Knob = Knob::choice(
    "penumbra",
    0.0,
    &["outer", "centred|centered"],
    "outer only (the papers), or centred on the hard edge",
);
