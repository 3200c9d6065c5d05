//! The constants that the host code and the shaders both read, written once. build.rs compiles
//! this file as a module of its own and defines each constant for every shader as a macro of
//! the same name (`#define MAX_WALK 32`, `#define RUN_STRAY (0.0625)`): a GLSL `int` from
//! `usize`, a `uint` from `u32`, a `float` from `f32`, a `vec2` from `[f32; 2]`. So only such
//! constants belong here, and their names are the shaders' too: each must be unique among every
//! shader's identifiers. A constant build.rs does not pass on warns as unused there.

/// Invocations per workgroup of every compute shader (`local_size_x`): the host divides its
/// dispatches by it.
pub const COMPUTE_GROUP: u32 = 64;

/// Marks the missing second face of a boundary edge (`geometry::adjacency`).
pub const NO_FACE: u32 = u32::MAX;

/// A surface's role in shadowing (`frame::ShadowRole`) as the prepass writes it into the
/// camera normal target's alpha.
pub const ROLE_IGNORES: f32 = 0.0;
pub const ROLE_RECEIVES: f32 = 0.5;
pub const ROLE_CASTS: f32 = 1.0;
/// What a role read back (perhaps rounded to a half float) is tested against: halfway between
/// two codes.
pub const ROLE_RECEIVES_ABOVE: f32 = 0.5 * (ROLE_IGNORES + ROLE_RECEIVES);
pub const ROLE_CASTS_ABOVE: f32 = 0.5 * (ROLE_RECEIVES + ROLE_CASTS);

/// The shadow-map family's resolve filters (`FILTER` of glsl/shadow_map/resolve.frag):
/// shadow-map's one 2x2 bilinear comparison, pcf's rotated Vogel disk or 4x4 B-spline, and
/// pcss's blocker search, penumbra estimate and PCF.
pub const FILTER_HARD: u32 = 0;
pub const FILTER_DISK: u32 = 1;
pub const FILTER_BICUBIC: u32 = 2;
pub const FILTER_PCSS: u32 = 3;

// The smoothies' geometry (`geometry::smoothie` on the CPU, glsl/smoothie/silhouettes.comp on
// the GPU: the same construction).

/// Floats per smoothie vertex (`geometry::smoothie::SmoothieVertex`).
pub const SMOOTHIE_VERTEX_FLOATS: usize = 26;

/// Nearest light depth, relative to the caster's own, a vertex may have and still be drawn.
pub const MIN_DEPTH: f32 = 1e-6;

/// How many times its own penumbra's width (on the farthest receiver) an inward partial
/// silhouette's sheet (`geometry::plateau::partial_sides`) or inner quad
/// (`geometry::smoothie::partial_smoothies`) may reach: an edge at contact has none, and its
/// umbra begins on its hard edge.
pub const MAX_INNER_REACH: f32 = 64.0;

/// What a smoothie that is no piece of a cut quad keeps (`SmoothieVertex::keep`): everything.
pub const KEEP_ALL: [f32; 2] = [f32::MIN, f32::MAX];

/// How far a cut quad's sliver over its base reaches from it (`geometry::smoothie`'s
/// `edge_quad`), in the rasterizer's subpixel steps (its `subPixelPrecisionBits`), by which the
/// rounded base of a piece may stray from the hard edge's line: four of them, 1/64 texel on
/// llvmpipe.
pub const SLIVER_STEPS: f32 = 4.0;

/// The most a cut quad's sliver reaches from its base, in its width: it stays inside the quad.
pub const SLIVER: f32 = 0.125;

/// How much of the other's part of the edge each of two pieces keeps at their cut: far more
/// than `along`'s rounding, a few 1e-7, and V there is the same from both to about as little,
/// the corner's difference having vanished at a cut (overlap: a lit speckle, V 0.78 for 0.50,
/// where neither kept a fragment).
pub const KEEP_SLACK: f32 = 1e-4;

/// The most vertices a walk along the hard shadow's outline passes (`geometry::smoothie`'s
/// `Outline`): a run or a search that needs more, on an outline cut finer than a 32nd of its
/// reach, finds no corner.
pub const MAX_WALK: usize = 32;

/// How far the edges of a run of the outline into a corner may turn from its chord
/// (`geometry::smoothie`'s `Run`), as a sine: a 16th of the corner's own turn (radians). A
/// polygon's side passes, straight or cut into edges that zigzag across it by far less; a
/// tessellated curve, whose edges at the run's ends turn from any chord by half the chord's own
/// turn, does not, and keeps its edges' own V, as the corners' reach keeps it where its edges
/// are long. Strays measured as the vertices' distances from the chord let a curve through
/// where its chord ends in one long edge (a corner on the sphere's outline darkened its shadow
/// on `default`: penumbra RMSE 0.0963 against 0.0868 with the edges' turns, 512², one run each).
pub const RUN_STRAY: f32 = 1.0 / 16.0;

/// silhouettes.comp's dispatches per caster, in order (its `STAGE`): pairing the silhouette
/// vertices' edge ends, finding each vertex's own corner, drawing; each reads what the ones
/// before wrote.
pub const STAGE_PAIR: u32 = 0;
pub const STAGE_OWN: u32 = 1;
pub const STAGE_DRAW: u32 = 2;

/// Words of a silhouette vertex's own corner in the stamps buffer (STAGE_OWN's): its at,
/// normals, turn and chamfer as float bits.
pub const CORNER_WORDS: u32 = 10;

/// Words per vertex in a mesh's stamps buffer: the stamped count, the first two edge ends
/// (STAGE_PAIR's) and the vertex's own corner.
pub const STAMP_WORDS: u32 = 3 + CORNER_WORDS;

// Shadow volumes (`technique::shadow_volume` on the CPU, glsl/shadow_volume/silhouettes.comp).

/// Floats per volume vertex: object-space position, at infinity (0 or 1), object index.
pub const VOLUME_VERTEX_FLOATS: usize = 5;

// Plateaus (`geometry::plateau`, glsl/plateau/).

/// The sides' records as the shaders read them (`geometry::plateau::Wedge`, `Sheet`), in vec4s.
pub const WEDGE_VEC4S: u32 = 4;
pub const SHEET_VEC4S: u32 = 7;

/// Most samples at which a centred sheet's mask probes are taken along its hard edge (a bit
/// each in 64-bit sets): longer sheets are drawn in pieces, for a sample every texel.
pub const SHEET_SAMPLES: u32 = 64;
const _: () = assert!(SHEET_SAMPLES <= 64);

/// How far the mask probes look from a hard edge, in texels: past the hard edge's
/// rasterisation.
pub const MASK_PROBE: f32 = 2.0;

/// Slack of the inverse map's s and t at a sheet's sides (f32 rounding): a fragment on a side
/// shared with a neighbour is drawn by both rather than by neither.
pub const SHEET_SLACK: f32 = 1e-4;

/// How near p, relative to the patch's size (the root of its sides' summed squares), a root
/// near a fold line must map back to count (where d rounds below 0, or s swings out of range
/// with t's rounding).
pub const FOLD_SLACK: f32 = 1e-4;
