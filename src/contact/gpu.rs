//! The normal contact solve on an NVIDIA GPU (the `gpu` feature; [`super::Device::Gpu`]).
//!
//! The iteration is the CPU's capped one ([`super::cpu`]'s `saturated` module): Polonsky &
//! Keer's constrained conjugate gradient on the free points, projected at 0 and at the hardness
//! H (H = +∞ without a cap), the load restored by p ← min(λp, H), the residual of
//! [`super::solver`] checked on u = K p recomputed every iteration. Each iteration is two FFT
//! pairs (K p and K t) and five passes over the window, each pass fused with its reductions.
//! Every field stays on the GPU; what crosses to the host per iteration is a few scalars: the
//! residual and gap norm (for the convergence test, the progress callback and the stall
//! restart) and the sums of the load restoration.
//!
//! The CUDA driver, cuFFT and NVRTC are found at run time (cudarc's dynamic loading): a build
//! with the feature runs everywhere, and `--device gpu` fails in one line naming what is
//! missing. The kernels (`gpu/kernels.cu`) are compiled by NVRTC for the device at set-up.
//!
//! Reductions add per-block partial sums in a fixed order, so a solve gives the same result on
//! every run; it differs from the CPU's by rounding and by the CPU elastic solve's one-pair
//! iteration, within the tolerance (the tests compare the two).
//!
//! Imports `options` and `influence` inside `contact`, never `solver` or `cpu`; must not import
//! friction, study, report, plot, shs, cli.

use std::sync::{Arc, OnceLock};
use std::time::Instant;

use cudarc::cufft::{result as fft, sys as fft_sys};
use cudarc::driver::{CudaContext, CudaFunction, CudaSlice, CudaStream, DevicePtr, LaunchConfig, PushKernelArg};
use cudarc::nvrtc::{compile_ptx_with_opts, CompileOptions, Ptx};

use super::influence::{free_coefficients, Boundary};
use super::options::{Engine, Iterations, Scales, SolveReport, SolverOptions, STALL};
use crate::error::{Error, Result};
use crate::limits::{check_memory, gib, grid_memory};

const KERNELS: &str = include_str!("gpu/kernels.cu");
/// Threads per block and blocks of every pass: as `TPB` and `NB` in the kernels.
const TPB: u32 = 256;
const NB: u32 = 1024;
/// Newton steps of the load restoration at most, as on the CPU.
const NEWTON: usize = 64;
/// Host bytes per window point besides the caller's heights: heights, pressure, displacement.
const HOST_BYTES_PER_POINT: u64 = 24;

/// An error of the GPU path, naming `--device`.
fn gpu_error(what: &str, e: impl std::fmt::Debug) -> Error {
    Error::invalid("--device", format!("gpu: {what}: {e:?}"))
}

/// The CUDA libraries the backend loads, each checked before its first use (cudarc panics on a
/// missing library otherwise).
fn check_libraries() -> Result<()> {
    // SAFETY: each only tries to open the shared library.
    let present = unsafe {
        [
            (cudarc::driver::sys::is_culib_present(), "the NVIDIA driver (libcuda.so) was not found: install it, or use --device cpu"),
            (cudarc::nvrtc::sys::is_culib_present(), "NVRTC (libnvrtc.so, CUDA toolkit) was not found: install the toolkit or put its lib64 folder on LD_LIBRARY_PATH"),
            (cudarc::cufft::sys::is_culib_present(), "cuFFT (libcufft.so, CUDA toolkit) was not found: install the toolkit or put its lib64 folder on LD_LIBRARY_PATH"),
        ]
    };
    match present.iter().find(|(ok, _)| !ok) {
        Some((_, missing)) => Err(Error::invalid("--device", format!("gpu: {missing}"))),
        None => Ok(()),
    }
}

/// A cuFFT plan, destroyed with its value.
struct Plan(fft_sys::cufftHandle);

impl Plan {
    /// A `kind` transform on the (gy, gx) grid on `stream`, its work area left to the caller;
    /// with the work area's size [bytes].
    fn new(stream: &CudaStream, (gy, gx): (usize, usize), kind: fft_sys::cufftType) -> Result<(Self, usize)> {
        let plan = Plan(fft::create().map_err(|e| gpu_error("cuFFT plan", e))?);
        // SAFETY: a valid plan, configured before its first use.
        let size = unsafe {
            fft::set_auto_allocation(plan.0, false)
                .and_then(|_| fft::make_plan_2d(plan.0, gy as i32, gx as i32, kind))
                .and_then(|size| fft::set_stream(plan.0, stream.cu_stream() as _).map(|_| size))
        }
        .map_err(|e| gpu_error("cuFFT plan", e))?;
        Ok((plan, size))
    }
}

impl Drop for Plan {
    fn drop(&mut self) {
        // SAFETY: made in `new`, used only through this value.
        let _ = unsafe { fft::destroy(self.0) };
    }
}

/// One real-to-complex and one complex-to-real plan on the grid, sharing one work area
/// (dropped after them: fields drop in order).
struct Plans {
    forward: Plan,
    inverse: Plan,
    _work: CudaSlice<u8>,
}

impl Plans {
    /// The plans, if `needed` bytes and their work area fit in the GPU's free memory.
    fn new(stream: &Arc<CudaStream>, grid: (usize, usize), free: u64, needed: u64, what: &str) -> Result<Self> {
        let (forward, a) = Plan::new(stream, grid, fft_sys::cufftType::CUFFT_D2Z)?;
        let (inverse, b) = Plan::new(stream, grid, fft_sys::cufftType::CUFFT_Z2D)?;
        let total = needed + a.max(b) as u64;
        if total > free {
            return Err(Error::invalid(
                "surface",
                format!("{what} needs about {} of GPU memory, more than the {} free", gib(total), gib(free)),
            ));
        }
        let work = stream.alloc_zeros::<u8>(a.max(b).max(1)).map_err(|e| gpu_error("allocation", e))?;
        {
            let (pointer, _sync) = work.device_ptr(stream);
            for plan in [&forward, &inverse] {
                // SAFETY: the work area outlives the plans (dropped after them).
                unsafe { fft::set_work_area(plan.0, pointer as *mut _) }
                    .map_err(|e| gpu_error("cuFFT work area", e))?;
            }
        }
        Ok(Plans { forward, inverse, _work: work })
    }
}

/// The compiled kernels.
struct Kernels {
    finish: CudaFunction,
    gap_mean: CudaFunction,
    residual: CudaFunction,
    direction: CudaFunction,
    curvature: CudaFunction,
    update: CudaFunction,
    newton: CudaFunction,
    sum: CudaFunction,
    scale: CudaFunction,
    start: CudaFunction,
    window_copy: CudaFunction,
    multiply: CudaFunction,
    periodic_kernel: CudaFunction,
    real_part: CudaFunction,
}

impl Kernels {
    fn compile(context: &Arc<CudaContext>) -> Result<Self> {
        // Compiled once per process (the study sets up a solver per sweep, on one device).
        static PTX: OnceLock<std::result::Result<Ptx, String>> = OnceLock::new();
        let ptx = PTX.get_or_init(|| {
            let (major, minor) = context.compute_capability().map_err(|e| format!("device: {e:?}"))?;
            let options = CompileOptions {
                options: vec![format!("--gpu-architecture=compute_{major}{minor}")],
                ..Default::default()
            };
            compile_ptx_with_opts(KERNELS, options).map_err(|e| format!("NVRTC: {e:?}"))
        });
        let ptx = ptx.clone().map_err(|e| Error::invalid("--device", format!("gpu: {e}")))?;
        let module = context.load_module(ptx).map_err(|e| gpu_error("kernels", e))?;
        let f = |name: &str| module.load_function(name).map_err(|e| gpu_error("kernels", e));
        Ok(Kernels {
            finish: f("finish")?,
            gap_mean: f("gap_mean_pass")?,
            residual: f("residual_pass")?,
            direction: f("direction_pass")?,
            curvature: f("curvature_pass")?,
            update: f("update_pass")?,
            newton: f("newton_pass")?,
            sum: f("sum_pass")?,
            scale: f("scale")?,
            start: f("start")?,
            window_copy: f("window_copy")?,
            multiply: f("multiply")?,
            periodic_kernel: f("periodic_kernel")?,
            real_part: f("real_part")?,
        })
    }
}

/// Scalars the passes leave on the GPU, each its own slot.
#[derive(Clone, Copy)]
enum Slot {
    /// [Σ_free (u − h), free count, max_saturated (u − h)]
    Mean = 0,
    /// [Σ p|g|, Σ g², Σ H max(g, 0), Σ max(−g, 0)]
    Residual = 4,
    /// [Σ g t, Σ t, free count]
    Direction = 8,
    /// [Σ Kt·t, Σ Kt]
    Curvature = 12,
    /// [changed, Σ p below H, Σ p at H, Σ p]
    Update = 16,
    /// [carried, slope] of a Newton step; [Σ p below H, Σ p at H, Σ p]
    Newton = 20,
}

const SLOTS: usize = 24;

/// The GPU engine of [`super::ContactSolver`].
pub(crate) struct GpuSolver {
    ny: usize,
    nx: usize,
    /// The FFT grid: the window (periodic) or the padded 2ny × 2nx grid (free).
    grid: (usize, usize),
    size: (f64, f64),
    boundary: Boundary,
    e_star: f64,
    h_rms: f64,
    options: SolverOptions,
    hardness: Option<f64>,
    warm: bool,
    /// Host copies: heights [m], the last solve's pressure [Pa], and its displacement [m]
    /// once asked for.
    heights: Vec<f64>,
    pressure: Vec<f64>,
    displacement: OnceLock<Vec<f64>>,
    stream: Arc<CudaStream>,
    kernels: Kernels,
    plans: Plans,
    h: CudaSlice<f64>,
    p: CudaSlice<f64>,
    t: CudaSlice<f64>,
    u: CudaSlice<f64>,
    kt: CudaSlice<f64>,
    spectrum: CudaSlice<fft_sys::double2>,
    kernel: CudaSlice<f64>,
    partials: CudaSlice<f64>,
    scalars: CudaSlice<f64>,
}

impl GpuSolver {
    /// The problem [`super::ContactSolver::new`] has checked, on the first CUDA device.
    pub(crate) fn new(
        heights: &[f64],
        (ny, nx): (usize, usize),
        size: (f64, f64),
        e_star: f64,
        boundary: Boundary,
        options: SolverOptions,
        h_rms: f64,
    ) -> Result<Self> {
        check_memory(grid_memory(nx, ny, HOST_BYTES_PER_POINT), &format!("a GPU contact solve on {nx} × {ny} points"))
            .map_err(|r| Error::invalid("surface", r))?;
        check_libraries()?;
        let context = CudaContext::new(0).map_err(|e| match e.0 {
            cudarc::driver::sys::CUresult::CUDA_ERROR_NO_DEVICE => {
                Error::invalid("--device", "gpu: no CUDA device found: use --device cpu")
            }
            _ => gpu_error("CUDA device 0", e),
        })?;
        // A stream of its own: the sweeps of a study run side by side on the device.
        let stream = context.new_stream().map_err(|e| gpu_error("CUDA stream", e))?;
        let kernels = Kernels::compile(&context)?;
        let grid = match boundary {
            Boundary::Periodic => (ny, nx),
            Boundary::Free => (2 * ny, 2 * nx),
        };
        let (gy, gx) = grid;
        let (points, spectrum_points) = (gy * gx, gy * (gx / 2 + 1));
        // h; p, t, u, Kt; the spectrum (complex) and the kernel (real).
        let needed = 8 * (ny * nx + 4 * points + 3 * spectrum_points) as u64;
        let free = context.mem_get_info().map_err(|e| gpu_error("device memory", e))?.0 as u64;
        let what = format!("a GPU contact solve on {nx} × {ny} points");
        let plans = Plans::new(&stream, grid, free, needed, &what)?;
        let alloc = |n: usize| stream.alloc_zeros::<f64>(n).map_err(|e| gpu_error("allocation", e));
        let h = stream.clone_htod(heights).map_err(|e| gpu_error("copy to the GPU", e))?;
        let mut solver = GpuSolver {
            ny,
            nx,
            grid,
            size,
            boundary,
            e_star,
            h_rms,
            options,
            hardness: None,
            warm: false,
            heights: heights.to_vec(),
            pressure: vec![0.0; ny * nx],
            displacement: OnceLock::new(),
            kernels,
            plans,
            h,
            p: alloc(points)?,
            t: alloc(points)?,
            u: alloc(points)?,
            kt: alloc(points)?,
            spectrum: stream.alloc_zeros(spectrum_points).map_err(|e| gpu_error("allocation", e))?,
            kernel: alloc(spectrum_points)?,
            partials: alloc(6 * NB as usize)?,
            scalars: alloc(SLOTS)?,
            stream,
        };
        solver.make_kernel()?;
        Ok(solver)
    }

    /// The launch of a pass over `m` points.
    fn config(m: usize) -> LaunchConfig {
        let blocks = m.div_ceil(TPB as usize).clamp(1, NB as usize) as u32;
        LaunchConfig { grid_dim: (blocks, 1, 1), block_dim: (TPB, 1, 1), shared_mem_bytes: 0 }
    }

    /// Every reduction pass runs on exactly NB blocks: `finish` reads all NB partials.
    fn reduction() -> LaunchConfig {
        LaunchConfig { grid_dim: (NB, 1, 1), block_dim: (TPB, 1, 1), shared_mem_bytes: 0 }
    }

    fn launched(
        r: std::result::Result<
            Option<(cudarc::driver::CudaEvent, cudarc::driver::CudaEvent)>,
            cudarc::driver::DriverError,
        >,
    ) -> Result<()> {
        r.map(|_| ()).map_err(|e| gpu_error("kernel launch", e))
    }

    /// The operator's kernel on the half spectrum, normalisation folded in.
    fn make_kernel(&mut self) -> Result<()> {
        let (gy, gx) = self.grid;
        let m = (gy * (gx / 2 + 1)) as i64;
        let norm = 1.0 / (gy * gx) as f64;
        let (gy_, gx_) = (gy as i64, gx as i64);
        match self.boundary {
            Boundary::Periodic => {
                let (lx, ly) = self.size;
                let mut b = self.stream.launch_builder(&self.kernels.periodic_kernel);
                b.arg(&mut self.kernel).arg(&gy_).arg(&gx_).arg(&lx).arg(&ly).arg(&self.e_star).arg(&norm);
                // SAFETY: the kernel writes m values of `kernel`, which has m.
                Self::launched(unsafe { b.launch(Self::config(m as usize)) })?;
            }
            Boundary::Free => {
                let coefficients = free_coefficients(self.ny, self.nx, self.size, self.e_star);
                self.stream.memcpy_htod(&coefficients, &mut self.kt).map_err(|e| gpu_error("copy to the GPU", e))?;
                self.forward_of_kt()?;
                let mut b = self.stream.launch_builder(&self.kernels.real_part);
                b.arg(&self.spectrum).arg(&mut self.kernel).arg(&m).arg(&norm);
                // SAFETY: m values read and written.
                Self::launched(unsafe { b.launch(Self::config(m as usize)) })?;
                // Kt is a scratch field: it held the coefficients, the padding included.
                self.stream.memset_zeros(&mut self.kt).map_err(|e| gpu_error("memset", e))?;
            }
        }
        Ok(())
    }

    /// spectrum ← FFT(kt).
    fn forward_of_kt(&mut self) -> Result<()> {
        let (input, _a) = self.kt.device_ptr(&self.stream);
        let (output, _b) = self.spectrum.device_ptr(&self.stream);
        // SAFETY: plan on the grid; kt has the grid's points, the spectrum its half spectrum.
        unsafe { fft::exec_d2z(self.plans.forward.0, input as *mut f64, output as *mut fft_sys::cufftDoubleComplex) }
            .map_err(|e| gpu_error("cuFFT", e))
    }

    /// out ← K x, for x and out fields on the grid (`x_is_p`: x = p, out = u; else x = t,
    /// out = Kt).
    fn apply(&mut self, x_is_p: bool) -> Result<()> {
        let (x, out) = if x_is_p { (&self.p, &self.u) } else { (&self.t, &self.kt) };
        let (gy, gx) = self.grid;
        let m = (gy * (gx / 2 + 1)) as i64;
        {
            let (input, _a) = x.device_ptr(&self.stream);
            let (spectrum, _b) = self.spectrum.device_ptr(&self.stream);
            // SAFETY: as in `forward_of_kt`.
            unsafe {
                fft::exec_d2z(self.plans.forward.0, input as *mut f64, spectrum as *mut fft_sys::cufftDoubleComplex)
            }
            .map_err(|e| gpu_error("cuFFT", e))?;
        }
        let mut b = self.stream.launch_builder(&self.kernels.multiply);
        b.arg(&mut self.spectrum).arg(&self.kernel).arg(&m);
        // SAFETY: m values of each.
        Self::launched(unsafe { b.launch(Self::config(m as usize)) })?;
        let (spectrum, _b) = self.spectrum.device_ptr(&self.stream);
        let (output, _c) = out.device_ptr(&self.stream);
        // SAFETY: the inverse plan; the spectrum is overwritten (cuFFT's C2R), the output has
        // the grid's points.
        unsafe { fft::exec_z2d(self.plans.inverse.0, spectrum as *mut fft_sys::cufftDoubleComplex, output as *mut f64) }
            .map_err(|e| gpu_error("cuFFT", e))
    }

    /// Add up the last pass's `k` partial sums (bit j of `max_mask`: a maximum) into `slot`.
    fn finish(&mut self, k: i32, max_mask: u32, slot: Slot) -> Result<()> {
        let mut out = self.scalars.slice_mut(slot as usize..slot as usize + k as usize);
        let mut b = self.stream.launch_builder(&self.kernels.finish);
        b.arg(&self.partials).arg(&k).arg(&max_mask).arg(&mut out);
        // SAFETY: reads k·NB partials, writes k scalars.
        Self::launched(unsafe {
            b.launch(LaunchConfig { grid_dim: (1, 1, 1), block_dim: (TPB, 1, 1), shared_mem_bytes: 0 })
        })
    }

    /// The scalars of `slot`, read back (the host waits for the GPU).
    fn read(&self, slot: Slot, k: usize) -> Result<Vec<f64>> {
        self.stream
            .clone_dtoh(&self.scalars.slice(slot as usize..slot as usize + k))
            .map_err(|e| gpu_error("copy from the GPU", e))
    }

    fn dims(&self) -> (i64, i64, i64) {
        ((self.ny * self.nx) as i64, self.nx as i64, self.grid.1 as i64)
    }

    fn cap(&self) -> f64 {
        self.hardness.unwrap_or(f64::INFINITY)
    }

    /// p ← λp everywhere (`all`), or min(λp, H) below H.
    fn scale(&mut self, lambda: f64, all: bool) -> Result<()> {
        let (n, nx, gx) = self.dims();
        let (hard, all) = (self.cap(), all as i32);
        let mut b = self.stream.launch_builder(&self.kernels.scale);
        b.arg(&mut self.p).arg(&n).arg(&nx).arg(&gx).arg(&hard).arg(&lambda).arg(&all);
        // SAFETY: window points of p.
        Self::launched(unsafe { b.launch(Self::config(n as usize)) })
    }

    /// Restore the load Σp = `total` as the CPU's `restore_load` does, from the sums
    /// [changed, Σ p below H, Σ p at H, Σ p] of the last update. Returns whether points were let
    /// in to carry it (the conjugacy then restarts).
    fn restore_load(&mut self, sums: [f64; 3], total: f64) -> Result<bool> {
        let [free, saturated, all] = sums;
        let hard = self.cap();
        if saturated >= total {
            self.scale(total / all, true)?;
        } else if free > 0.0 {
            let mut lambda = (total - saturated) / free;
            if hard.is_finite() {
                let (n, nx, gx) = self.dims();
                for _ in 0..NEWTON {
                    let mut b = self.stream.launch_builder(&self.kernels.newton);
                    b.arg(&self.p).arg(&n).arg(&nx).arg(&gx).arg(&hard).arg(&lambda).arg(&mut self.partials);
                    // SAFETY: reads window points of p, writes NB·2 partials.
                    Self::launched(unsafe { b.launch(Self::reduction()) })?;
                    self.finish(2, 0, Slot::Newton)?;
                    let s = self.read(Slot::Newton, 2)?;
                    let missing = total - s[0];
                    if missing <= 1e-15 * total || s[1] == 0.0 {
                        break;
                    }
                    lambda += missing / s[1];
                }
            }
            self.scale(lambda, false)?;
        }
        if !hard.is_finite() {
            // Uncapped, λ carries the load to rounding.
            return Ok(false);
        }
        let missing = total - self.sums_of_p()?[2];
        if missing <= 1e-12 * total {
            return Ok(false);
        }
        self.fill(missing, hard)?;
        Ok(true)
    }

    /// The rest of the load, at H each, to the points out of contact with the smallest u − h
    /// (the points in contact cannot carry it saturated). Rare: done on the host.
    fn fill(&mut self, mut missing: f64, hard: f64) -> Result<()> {
        let p = self.window(false)?;
        let u = self.window(true)?;
        let h = &self.heights;
        let mut out: Vec<(f64, u32)> =
            p.iter().enumerate().filter(|(_, q)| **q == 0.0).map(|(i, _)| (u[i] - h[i], i as u32)).collect();
        let k = ((missing / hard).ceil() as usize).clamp(1, out.len().max(1));
        if out.is_empty() {
            return Ok(());
        }
        out.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out.truncate(k);
        out.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut p = p;
        for (_, i) in out {
            let q = missing.min(hard);
            p[i as usize] = q;
            missing -= q;
        }
        self.upload_pressure(&p)
    }

    /// The window of p (or of u), copied to the host through Kt (a scratch field between
    /// iterations).
    fn window(&mut self, of_u: bool) -> Result<Vec<f64>> {
        let (n, nx, gx) = self.dims();
        let to = 0i32;
        let src = if of_u { &self.u } else { &self.p };
        let mut b = self.stream.launch_builder(&self.kernels.window_copy);
        b.arg(src).arg(&mut self.kt).arg(&n).arg(&nx).arg(&gx).arg(&to);
        // SAFETY: n window points read, n compact points written (Kt has the grid's ≥ n).
        Self::launched(unsafe { b.launch(Self::config(n as usize)) })?;
        self.stream.clone_dtoh(&self.kt.slice(..n as usize)).map_err(|e| gpu_error("copy from the GPU", e))
    }

    /// p on the window ← `pressure` (compact, ny × nx), through Kt.
    fn upload_pressure(&mut self, pressure: &[f64]) -> Result<()> {
        let (n, nx, gx) = self.dims();
        let mut staged = self.kt.slice_mut(..n as usize);
        self.stream.memcpy_htod(pressure, &mut staged).map_err(|e| gpu_error("copy to the GPU", e))?;
        let to = 1i32;
        let mut b = self.stream.launch_builder(&self.kernels.window_copy);
        b.arg(&self.kt).arg(&mut self.p).arg(&n).arg(&nx).arg(&gx).arg(&to);
        // SAFETY: n compact points read, n window points written.
        Self::launched(unsafe { b.launch(Self::config(n as usize)) })
    }
}

impl Engine for GpuSolver {
    fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    fn size(&self) -> (f64, f64) {
        self.size
    }

    fn boundary(&self) -> Boundary {
        self.boundary
    }

    fn e_star(&self) -> f64 {
        self.e_star
    }

    fn hardness(&self) -> Option<f64> {
        self.hardness
    }

    fn heights(&self) -> &[f64] {
        &self.heights
    }

    fn pressure(&self) -> &[f64] {
        &self.pressure
    }

    fn displacement(&self) -> &[f64] {
        self.displacement.get_or_init(|| {
            // The whole grid: the window is its top-left corner.
            let u = self.stream.clone_dtoh(&self.u).expect("reading back the displacement from the GPU");
            let gx = self.grid.1;
            (0..self.ny * self.nx).map(|i| u[(i / self.nx) * gx + i % self.nx]).collect()
        })
    }

    fn reset(&mut self) {
        self.warm = false;
    }

    fn set_hardness(&mut self, hardness: Option<f64>) {
        self.hardness = hardness;
    }

    fn set_tolerance(&mut self, tolerance: f64) {
        self.options.convergence.tolerance = tolerance;
    }

    /// The GPU's start transforms the pressure every time.
    fn set_rescaled_start(&mut self, _on: bool) {}

    fn set_heights(&mut self, heights: &[f64], h_rms: f64) -> Result<()> {
        self.stream.memcpy_htod(heights, &mut self.h).map_err(|e| gpu_error("copy to the GPU", e))?;
        self.heights.copy_from_slice(heights);
        self.h_rms = h_rms;
        Ok(())
    }

    fn warm_start(&mut self, pressure: &[f64]) -> Result<()> {
        self.upload_pressure(pressure)?;
        self.pressure.copy_from_slice(pressure);
        self.warm = true;
        Ok(())
    }

    fn solve(&mut self, load: f64, progress: &mut dyn FnMut(usize, f64) -> bool) -> Result<SolveReport> {
        let report = self.iterate(load, progress);
        match &report {
            Ok(_) => {
                self.pressure = self.window(false)?;
                self.displacement = OnceLock::new();
                self.warm = true;
            }
            Err(_) => {
                // A failed solve is no warm start, and leaves no pressure.
                self.warm = false;
                self.pressure.fill(0.0);
            }
        }
        report
    }
}

impl GpuSolver {
    fn iterate(&mut self, load: f64, progress: &mut dyn FnMut(usize, f64) -> bool) -> Result<SolveReport> {
        let started = Instant::now();
        let (ny, nx) = (self.ny, self.nx);
        let n = ny * nx;
        let hard = self.cap();
        let Scales { p_mean, total, norm, stiffness } =
            Scales::of(hard, load, self.size, (ny, nx), self.e_star, self.h_rms)?;
        let fallback_step = 1.0 / stiffness;
        let (nn, nxx, gx) = self.dims();
        {
            let value = if self.warm { -1.0 } else { p_mean };
            let mut b = self.stream.launch_builder(&self.kernels.start);
            b.arg(&mut self.p).arg(&nn).arg(&nxx).arg(&gx).arg(&hard).arg(&value);
            // SAFETY: window points of p.
            Self::launched(unsafe { b.launch(Self::config(n)) })?;
        }
        self.apply(true)?;
        let sums = self.sums_of_p()?;
        self.restore_load(sums, total)?;

        let mut iterations = Iterations::new("contact solver", self.options.convergence, STALL);
        let mut applications = 1.0;
        let (mut conjugate, mut gap_norm_old) = (false, 1.0);
        let residual = loop {
            self.apply(true)?;
            applications += 1.0;
            self.pass_over_gaps()?;
            let r = self.read(Slot::Residual, 4)?;
            let residual = (r[0] + r[2] + p_mean * r[3]) / norm;
            let gap_norm = r[1];
            if iterations.done() > 0 && !progress(iterations.done(), residual) {
                return Err(Error::Interrupted { what: format!("contact solve at {load} N") });
            }
            if residual <= self.options.convergence.tolerance {
                break residual;
            }
            if iterations.next(residual)? {
                conjugate = false;
            }
            let beta = if conjugate && gap_norm_old > 0.0 { gap_norm / gap_norm_old } else { 0.0 };
            gap_norm_old = gap_norm;
            self.pass_direction(beta)?;
            self.apply(false)?;
            applications += 1.0;
            self.pass_update(fallback_step)?;
            let u = self.read(Slot::Update, 4)?;
            let filled = self.restore_load([u[1], u[2], u[3]], total)?;
            conjugate = !(filled || u[0] > 0.0);
        };
        Ok(SolveReport {
            load,
            mean_pressure: p_mean,
            iterations: iterations.done(),
            residual,
            operator_applications: applications,
            seconds: started.elapsed().as_secs_f64(),
            hardness: self.hardness,
        })
    }

    /// [Σ p below H, Σ p at H, Σ p] of the pressure as it stands.
    fn sums_of_p(&mut self) -> Result<[f64; 3]> {
        let (n, nx, gx) = self.dims();
        let hard = self.cap();
        let mut b = self.stream.launch_builder(&self.kernels.sum);
        b.arg(&self.p).arg(&n).arg(&nx).arg(&gx).arg(&hard).arg(&mut self.partials);
        // SAFETY: reads window points of p, writes NB·3 partials.
        Self::launched(unsafe { b.launch(Self::reduction()) })?;
        self.finish(3, 0, Slot::Newton)?;
        let s = self.read(Slot::Newton, 3)?;
        Ok([s[0], s[1], s[2]])
    }

    /// The gap mean ḡ, then the residual's sums.
    fn pass_over_gaps(&mut self) -> Result<()> {
        let (n, nx, gx) = self.dims();
        let hard = self.cap();
        let mut b = self.stream.launch_builder(&self.kernels.gap_mean);
        b.arg(&self.p).arg(&self.u).arg(&self.h).arg(&n).arg(&nx).arg(&gx).arg(&hard).arg(&mut self.partials);
        // SAFETY: window points read; NB·3 partials written.
        Self::launched(unsafe { b.launch(Self::reduction()) })?;
        self.finish(3, 0b100, Slot::Mean)?;
        let mean = self.scalars.slice(Slot::Mean as usize..Slot::Mean as usize + 3);
        let mut b = self.stream.launch_builder(&self.kernels.residual);
        b.arg(&self.p).arg(&self.u).arg(&self.h).arg(&n).arg(&nx).arg(&gx).arg(&hard).arg(&mean);
        b.arg(&mut self.partials);
        // SAFETY: window points read; NB·4 partials written.
        Self::launched(unsafe { b.launch(Self::reduction()) })?;
        drop(b);
        self.finish(4, 0, Slot::Residual)
    }

    /// t ← g + β t on the free points, with its sums.
    fn pass_direction(&mut self, beta: f64) -> Result<()> {
        let (n, nx, gx) = self.dims();
        let hard = self.cap();
        let mean = self.scalars.slice(Slot::Mean as usize..Slot::Mean as usize + 3);
        let mut b = self.stream.launch_builder(&self.kernels.direction);
        b.arg(&self.p).arg(&self.u).arg(&self.h).arg(&mut self.t).arg(&n).arg(&nx).arg(&gx).arg(&hard);
        b.arg(&mean).arg(&beta).arg(&mut self.partials);
        // SAFETY: window points read and t written; NB·3 partials written.
        Self::launched(unsafe { b.launch(Self::reduction()) })?;
        drop(b);
        self.finish(3, 0, Slot::Direction)
    }

    /// The curvature along t, then the step and projection with the restoration's sums.
    fn pass_update(&mut self, fallback_step: f64) -> Result<()> {
        let (n, nx, gx) = self.dims();
        let hard = self.cap();
        let mut b = self.stream.launch_builder(&self.kernels.curvature);
        b.arg(&self.p).arg(&self.t).arg(&self.kt).arg(&n).arg(&nx).arg(&gx).arg(&hard).arg(&mut self.partials);
        // SAFETY: window points read; NB·2 partials written.
        Self::launched(unsafe { b.launch(Self::reduction()) })?;
        self.finish(2, 0, Slot::Curvature)?;
        let s = |slot: Slot, k: usize| self.scalars.slice(slot as usize..slot as usize + k);
        let (mean, dir, curv) = (s(Slot::Mean, 3), s(Slot::Direction, 3), s(Slot::Curvature, 2));
        let mut b = self.stream.launch_builder(&self.kernels.update);
        b.arg(&mut self.p).arg(&self.u).arg(&self.h).arg(&self.t).arg(&n).arg(&nx).arg(&gx).arg(&hard);
        b.arg(&mean).arg(&dir).arg(&curv).arg(&fallback_step).arg(&mut self.partials);
        // SAFETY: window points of p read and written; NB·4 partials written.
        Self::launched(unsafe { b.launch(Self::reduction()) })?;
        drop(b);
        self.finish(4, 0, Slot::Update)
    }
}
