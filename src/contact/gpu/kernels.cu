// The GPU normal solve's kernels, compiled at run time by NVRTC (see gpu.rs).
//
// Fields: the window's n = ny·nx points live in a grid of gy·gx points (the window itself for
// the periodic operator, the zero-padded 2ny × 2nx grid for the free one); heights are stored
// compact (n), every other field on the grid. Window point i is grid point (i / nx)·gx + i % nx.
//
// Every reduction is two launches: a pass over the window whose blocks write their partial
// sums (K quantities, `partials[k·NB + block]`), then `finish`, one block that adds them in a
// fixed order. Results do not depend on scheduling.
//
// Pressures are classed as in the CPU's capped solve: free 0 < p < H, out p = 0, saturated
// p = H (H = +inf without a cap).

#define TPB 256
#define NB 1024
#define WARPS (TPB / 32)
#define NEG_INF __longlong_as_double(0xfff0000000000000ULL)

typedef long long idx;

__device__ __forceinline__ idx grid_index(idx i, idx nx, idx gx) {
    // The periodic grid is the window: no 64-bit division.
    return nx == gx ? i : (i / nx) * gx + (i % nx);
}

__device__ __forceinline__ double warp_reduce(double v, bool max) {
    for (int o = 16; o > 0; o >>= 1) {
        double w = __shfl_down_sync(0xffffffffu, v, o);
        v = max ? fmax(v, w) : v + w;
    }
    return v;
}

// Block-reduce K values (bit k of max_mask: a maximum, else a sum) into partials[k·NB + block].
template <int K>
__device__ void block_reduce(double (&v)[K], double *partials, unsigned max_mask) {
    __shared__ double s[K][WARPS];
    int lane = threadIdx.x & 31, warp = threadIdx.x >> 5;
#pragma unroll
    for (int k = 0; k < K; k++) {
        double r = warp_reduce(v[k], (max_mask >> k) & 1);
        if (lane == 0) s[k][warp] = r;
    }
    __syncthreads();
    if (warp == 0) {
#pragma unroll
        for (int k = 0; k < K; k++) {
            bool max = (max_mask >> k) & 1;
            double r = lane < WARPS ? s[k][lane] : (max ? NEG_INF : 0.0);
            r = warp_reduce(r, max);
            if (lane == 0) partials[k * NB + blockIdx.x] = r;
        }
    }
}

// out[k] = the sum (or maximum) of partials[k·NB .. k·NB + NB): one block of TPB threads.
extern "C" __global__ void finish(const double *partials, int k_count, unsigned max_mask, double *out) {
    __shared__ double s[TPB];
    for (int k = 0; k < k_count; k++) {
        bool max = (max_mask >> k) & 1;
        double v = max ? NEG_INF : 0.0;
        for (int j = threadIdx.x; j < NB; j += TPB) {
            double w = partials[k * NB + j];
            v = max ? fmax(v, w) : v + w;
        }
        s[threadIdx.x] = v;
        __syncthreads();
        for (int w = TPB / 2; w > 0; w >>= 1) {
            if (threadIdx.x < w) s[threadIdx.x] = max ? fmax(s[threadIdx.x], s[threadIdx.x + w]) : s[threadIdx.x] + s[threadIdx.x + w];
            __syncthreads();
        }
        if (threadIdx.x == 0) out[k] = s[0];
        __syncthreads();
    }
}

// ḡ from the gap-mean pass: the mean of u − h over the free points, else the largest u − h
// over the saturated ones.
__device__ __forceinline__ double gap_mean(const double *m) {
    return m[1] > 0.0 ? m[0] / m[1] : m[2];
}

// [Σ_free (u − h), free count, max_saturated (u − h)]
extern "C" __global__ void gap_mean_pass(const double *p, const double *u, const double *h, idx n, idx nx, idx gx,
                                         double hard, double *partials) {
    double v[3] = {0.0, 0.0, NEG_INF};
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        idx g = grid_index(i, nx, gx);
        double q = p[g], d = u[g] - h[i];
        if (q == hard) {
            v[2] = fmax(v[2], d);
        } else if (q > 0.0) {
            v[0] += d;
            v[1] += 1.0;
        }
    }
    block_reduce<3>(v, partials, 4u);
}

// [free: Σ p|g|, Σ g²; saturated: Σ H max(g, 0); out: Σ max(−g, 0)], g = u − h − ḡ.
extern "C" __global__ void residual_pass(const double *p, const double *u, const double *h, idx n, idx nx, idx gx,
                                         double hard, const double *mean, double *partials) {
    double gbar = gap_mean(mean);
    double v[4] = {0.0, 0.0, 0.0, 0.0};
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        idx j = grid_index(i, nx, gx);
        double q = p[j], g = u[j] - h[i] - gbar;
        if (q == 0.0) {
            v[3] += fmax(-g, 0.0);
        } else if (q == hard) {
            v[2] += hard * fmax(g, 0.0);
        } else {
            v[0] += q * fabs(g);
            v[1] += g * g;
        }
    }
    block_reduce<4>(v, partials, 0u);
}

// t ← g + β t on the free points, 0 elsewhere; [Σ g t, Σ t, free count].
extern "C" __global__ void direction_pass(const double *p, const double *u, const double *h, double *t, idx n, idx nx,
                                          idx gx, double hard, const double *mean, double beta, double *partials) {
    double gbar = gap_mean(mean);
    double v[3] = {0.0, 0.0, 0.0};
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        idx j = grid_index(i, nx, gx);
        double q = p[j];
        if (q > 0.0 && q < hard) {
            double g = u[j] - h[i] - gbar;
            double d = g + beta * t[j];
            t[j] = d;
            v[0] += g * d;
            v[1] += d;
            v[2] += 1.0;
        } else {
            t[j] = 0.0;
        }
    }
    block_reduce<3>(v, partials, 0u);
}

// [Σ_free Kt·t, Σ_free Kt]
extern "C" __global__ void curvature_pass(const double *p, const double *t, const double *kt, idx n, idx nx, idx gx,
                                          double hard, double *partials) {
    double v[2] = {0.0, 0.0};
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        idx j = grid_index(i, nx, gx);
        double q = p[j];
        if (q > 0.0 && q < hard) {
            v[0] += kt[j] * t[j];
            v[1] += kt[j];
        }
    }
    block_reduce<2>(v, partials, 0u);
}

// The step, the projection at both bounds, and the sums the load restoration needs:
// [points let in or out of saturation, Σ p over p < H, Σ p over p = H, Σ p].
// dir = [Σ g t, Σ t, free count]; curv = [Σ Kt·t, Σ Kt].
extern "C" __global__ void update_pass(double *p, const double *u, const double *h, const double *t, idx n, idx nx,
                                       idx gx, double hard, const double *mean, const double *dir, const double *curv,
                                       double fallback_step, double *partials) {
    double gbar = gap_mean(mean);
    double curvature = dir[2] > 0.0 ? curv[0] - curv[1] / dir[2] * dir[1] : 0.0;
    double step = (curvature > 0.0 && dir[0] > 0.0) ? dir[0] / curvature : fallback_step;
    double v[4] = {0.0, 0.0, 0.0, 0.0};
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        idx j = grid_index(i, nx, gx);
        double q = p[j], g = u[j] - h[i] - gbar;
        if (q > 0.0 && q < hard) {
            q = fmin(fmax(q - step * t[j], 0.0), hard);
        } else if (q == 0.0 && g < 0.0) {
            q = fmin(-step * g, hard);
            v[0] += 1.0;
        } else if (q == hard && g > 0.0) {
            q = fmax(hard - step * g, 0.0);
            v[0] += 1.0;
        }
        p[j] = q;
        if (q == hard) {
            v[2] += q;
        } else {
            v[1] += q;
        }
        v[3] += q;
    }
    block_reduce<4>(v, partials, 0u);
}

// [Σ min(λp, H) (saturated points at H), Σ p over the points below H at λ]: one Newton step of
// the load restoration.
extern "C" __global__ void newton_pass(const double *p, idx n, idx nx, idx gx, double hard, double lambda,
                                       double *partials) {
    double v[2] = {0.0, 0.0};
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        double q = p[grid_index(i, nx, gx)];
        if (q == hard || lambda * q >= hard) {
            v[0] += hard;
        } else {
            v[0] += lambda * q;
            v[1] += q;
        }
    }
    block_reduce<2>(v, partials, 0u);
}

// [Σ p below H, Σ p at H, Σ p]
extern "C" __global__ void sum_pass(const double *p, idx n, idx nx, idx gx, double hard, double *partials) {
    double v[3] = {0.0, 0.0, 0.0};
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        double q = p[grid_index(i, nx, gx)];
        if (q == hard) {
            v[1] += q;
        } else {
            v[0] += q;
        }
        v[2] += q;
    }
    block_reduce<3>(v, partials, 0u);
}

// p ← λp everywhere (all), or p ← min(λp, H) where p < H.
extern "C" __global__ void scale(double *p, idx n, idx nx, idx gx, double hard, double lambda, int all) {
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        idx j = grid_index(i, nx, gx);
        double q = p[j];
        if (all) {
            p[j] = lambda * q;
        } else if (q < hard) {
            p[j] = fmin(lambda * q, hard);
        }
    }
}

// p ← value on the window (a cold start), or p ← min(p, H) (a warm one: value < 0).
extern "C" __global__ void start(double *p, idx n, idx nx, idx gx, double hard, double value) {
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        idx j = grid_index(i, nx, gx);
        p[j] = value >= 0.0 ? value : fmin(p[j], hard);
    }
}

// dst[i] = src[grid point of i] (to = 0), or dst[grid point of i] = src[i] (to = 1).
extern "C" __global__ void window_copy(const double *src, double *dst, idx n, idx nx, idx gx, int to) {
    for (idx i = blockIdx.x * (idx)TPB + threadIdx.x; i < n; i += (idx)NB * TPB) {
        idx j = grid_index(i, nx, gx);
        if (to) {
            dst[j] = src[i];
        } else {
            dst[i] = src[j];
        }
    }
}

// spectrum ← spectrum × kernel (real).
extern "C" __global__ void multiply(double2 *spectrum, const double *kernel, idx m) {
    for (idx k = blockIdx.x * (idx)TPB + threadIdx.x; k < m; k += (idx)NB * TPB) {
        double c = kernel[k];
        double2 s = spectrum[k];
        spectrum[k] = make_double2(s.x * c, s.y * c);
    }
}

// The periodic (Westergaard) kernel 2 / (E* |q|) × norm on the gy × (gx/2 + 1) half spectrum,
// zero at q = 0.
extern "C" __global__ void periodic_kernel(double *kernel, idx gy, idx gx, double lx, double ly, double e_star,
                                           double norm) {
    idx w = gx / 2 + 1, m = gy * w;
    const double two_pi = 6.283185307179586;
    for (idx k = blockIdx.x * (idx)TPB + threadIdx.x; k < m; k += (idx)NB * TPB) {
        idx ky = k / w, kx = k % w;
        double fy = (double)(ky <= gy / 2 ? ky : ky - gy);
        double qx = two_pi * (double)kx / lx, qy = two_pi * fy / ly;
        double q = sqrt(qx * qx + qy * qy);
        kernel[k] = q == 0.0 ? 0.0 : 2.0 / (e_star * q) * norm;
    }
}

// kernel ← Re(spectrum) × norm: the free boundary's kernel from its coefficients' transform.
extern "C" __global__ void real_part(const double2 *spectrum, double *kernel, idx m, double norm) {
    for (idx k = blockIdx.x * (idx)TPB + threadIdx.x; k < m; k += (idx)NB * TPB) kernel[k] = spectrum[k].x * norm;
}
