//! asperity: the static friction coefficient of rough interfaces from their measured
//! topography, after Peng, Roch, Bonn & Weber, Phys. Rev. Lett. 134, 176202 (2025).
//!
//! A measured (or synthetic) height map is pressed elastically onto a flat at a normal load N;
//! each contact pixel is an element carrying a normal force n_i = p_i · a. In the stick-slip
//! transition model the elements slip one after the other when the tangential force they
//! share reaches mu_s n_i, a slipped element then carrying mu_d n_i; the largest tangential
//! force along the way is the static friction force F_S. The interface's static coefficient
//! F_S / N lies between the local mu_d and mu_s, and the friction drop F_S / (mu_d N) between 1
//! (many elements) and mu_s / mu_d (one element carrying the whole load).
//!
//! Units are SI everywhere: metres, pascals, newtons. Arrays are row-major, shape (ny, nx).
//!
//! # Modules, in pipeline order
//!
//! - [`topography`]: read a measured file ([`topography::io`]: AFM, profilometer and optical
//!   instrument formats), prepare it
//!   ([`topography::prepare`]: crop, missing points, levelling, resampling, a ball's curvature),
//!   or synthesise a self-affine surface ([`topography::synth`]); its statistics.
//! - [`contact`]: elastic normal contact at imposed load by the boundary integral method
//!   (the Polonsky–Keer conjugate gradient on an FFT grid, [`fft`]); contact patches; the
//!   tangential solve of elastic sharing.
//! - [`friction`]: the stick-slip transition model at the onset of sliding ([`friction::Onset`],
//!   equal sharing as in the paper; [`friction::ElasticOnset`], elastic sharing), local
//!   friction laws, friction curves.
//! - [`study`]: topographies × loads × friction laws, resumable and shardable, as a results
//!   table and the data behind the figures.
//! - [`plot`] and [`report`]: the figures and the HTML report of a study.
//! - [`shs`]: slide-hold-slide experiments, from a measured friction trace to the points the
//!   figures compare with.
//!
//! Beside the pipeline: [`quantity`] (numbers with units as people write them), [`plausible`]
//! (ranges a value must lie in), [`limits`] (how large an input may be), [`output`] (atomic,
//! resumable writing), [`error`].
//!
//! Must not name the command line or Python: the library knows nothing of its front ends, and no
//! module imports a later one (docs/architecture.md).
//!
//! # Example: from a measured file to the static friction coefficient
//!
//! An AFM scan (`mi-1.mi`, a 20 µm square, 256 × 256 points, from SurfaceTopography's example
//! files; see `tests/data/README.md`) levelled by a plane and put on the curvature of a
//! 1.5 mm-radius ball, as a ball scanned with its curvature levelled away; silicon on a rigid
//! flat at 1 mN; the stick-slip onset with the local law mu_s = 0.6, mu_d = 0.4.
//!
//! ```
//! use asperity::contact::{contact_size, Boundary, ContactSolver, Material, SolverOptions};
//! use asperity::friction::{ElementLoads, FrictionLaw, Onset};
//! use asperity::topography::detrend::Detrend;
//! use asperity::topography::io::{self, ReadOptions};
//! use asperity::topography::prepare::Preparation;
//! use asperity::topography::synth::{Cap, CapShape};
//!
//! # fn main() -> asperity::Result<()> {
//! // Read: heights in metres, the file's physical size.
//! let scan = io::read("tests/data/mi-1.mi".as_ref(), &ReadOptions::default())?;
//! // Prepare: subtract the best-fit plane, then add the ball's curvature (R = 1.5 mm).
//! let preparation = Preparation {
//!     detrend: Detrend::Polynomial(1),
//!     cap: Some(Cap { radius: 1.5e-3, shape: CapShape::Sphere }),
//!     ..Preparation::default()
//! };
//! let surface = preparation.apply(scan)?;
//! let (lx, ly) = contact_size(&surface)?; // [m]
//! let (ny, nx) = surface.heights.dim();
//! assert_eq!((ny, nx), (256, 256));
//!
//! // Elastic normal contact at N = 1 mN: silicon (E = 130 GPa, ν = 0.26) on a rigid flat.
//! let e_star = Material::SILICON.plane_strain_modulus(); // [Pa]
//! let heights: Vec<f64> = surface.heights.iter().copied().collect();
//! let options = SolverOptions::default();
//! let mut solver = ContactSolver::new(&heights, (ny, nx), (lx, ly), e_star, Boundary::Periodic,
//! options)?;
//! let load = 1e-3; // [N]
//! solver.solve(load, |_, _| {})?;
//!
//! // The stick-slip onset: each contact pixel an element of force n_i = p_i · a.
//! let pressure = ndarray::ArrayView2::from_shape((ny, nx), solver.pressure()).unwrap(); // [Pa]
//! let pixel_area = (lx / nx as f64) * (ly / ny as f64); // [m²]
//! let law = FrictionLaw::new(0.6, 0.4)?;
//! let onset = Onset::new(&ElementLoads::from_pressure(&pressure, pixel_area)?, &law);
//!
//! assert!((onset.normal_force / load - 1.0).abs() < 1e-6); // the map carries the load
//! assert!(onset.elements > 1);
//! let (mu, drop) = (onset.static_coefficient(), onset.friction_drop());
//! assert!((0.4..=0.6).contains(&mu)); // mu_d ≤ F_S / N ≤ mu_s
//! assert!((1.0..=1.5).contains(&drop)); // 1 ≤ F_S / (mu_d N) ≤ mu_s / mu_d
//! println!("{} elements: static coefficient {mu:.4}, friction drop {drop:.4}", onset.elements);
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]

pub mod contact;
pub mod error;
pub mod fft;
pub mod friction;
pub mod limits;
pub mod output;
pub mod plausible;
pub mod plot;
pub mod quantity;
pub mod report;
pub mod shs;
pub mod study;
pub mod topography;

pub use error::{Error, Result};

/// This asperity's version (the crate's, `0.2.0`), as `--version`, `results.json` and the report
/// state it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The commit this asperity was built from: a short git hash, with `-modified` when its tracked
/// sources differed from that commit, or `unknown` when built outside a git checkout.
pub const COMMIT: &str = env!("ASPERITY_COMMIT");
