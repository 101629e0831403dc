/*
 * The PTO law, eq. (35) with the saturated linear zone of eq. (34), in C99.
 *
 * A port of the reference ptoverify.laws.pto_law (corrected variant), written as drive
 * firmware would be: no allocation, no globals, no state between calls, <math.h> only.
 * The switching-zone level omega0 (eqs. 19-27, corrected) is a design constant computed
 * offline (`ptoverify zone --json`, key corrected.omega0) and passed in with the gains.
 *
 * Build (double):  cc -std=c99 -O2 -shared -fPIC pto_law.c -o libpto.so -lm
 * Build (single):  add -DPTO_SINGLE: every computation in float, as on an FPU-less-double MCU.
 *
 * Units: x1 [mm], x2 [mm/s], a [rad/s], w_max [mm/s], d [mm], k1 [1/s], k2 [-], u [mm/s].
 */
#include <float.h>
#include <math.h>

#ifdef PTO_SINGLE
typedef float real;
#define LOG1P log1pf
#define EXPM1 expm1f
#define REAL_EPS FLT_EPSILON
#else
typedef double real;
#define LOG1P log1p
#define EXPM1 expm1
#define REAL_EPS DBL_EPSILON
#endif

typedef struct {
    double a;      /* bandwidth [rad/s] */
    double w_max;  /* saturation [mm/s] */
    double d;      /* half-width of the linear zone [mm] */
    double k1;     /* linear-zone position gain [1/s] */
    double k2;     /* linear-zone velocity gain [-] */
    double omega0; /* level of l1*, l2* [mm/s]; outside (0, w_max): no zone */
} pto_params;

/* h(r) = r - ln(1 + r), exact near 0 (series r^2/2 - r^3/3 + ...). */
static real h(real r)
{
    if (r > (real)-0.2 && r < (real)0.2) {
        real acc = 0;
        int n;
        for (n = 25; n >= 2; --n) {
            acc = acc * r + (real)((n % 2 ? -1.0 : 1.0) / n);
        }
        return acc * r * r;
    }
    return r - LOG1P(r);
}

/* Level-omega curve through the origin, eqs. (9), (11), (13), (14): > 0 right of it. */
static real sigma(real x1, real x2, real a, real omega)
{
    if (x2 > 0) {
        return a * x1 + omega * h(x2 / omega);
    }
    if (x2 < 0) {
        return a * x1 - omega * h(-x2 / omega);
    }
    return a * x1;
}

/* Level omega_c of the curve through (x1, x2), eqs. (28)-(32): Newton on u = ln(1 + w). */
static real omega_c(real x1, real x2, real a)
{
    real m = -a * x1 / x2;
    real u, g, dg, e, du;
    int i;
    if (m <= 0) {
        return (real)INFINITY;
    }
    if (m >= 1) {
        return 0;
    }
    u = 2 * m;
    for (i = 0; i < 60; ++i) {
        if (u < (real)1e-3) {
            g = u * ((real)0.5 - u * ((real)(1.0 / 12.0) - u * u / (real)720.0)) - m;
            dg = (real)0.5 - u / (real)6.0;
        } else {
            e = EXPM1(u);
            g = 1 - u / e - m;
            dg = ((u - 1) * e + u) / (e * e);
        }
        du = g / dg;
        u -= du;
        if (fabs((double)du) <= 2 * REAL_EPS * (double)u) {
            break;
        }
    }
    return (real)fabs((double)x2) / EXPM1(u);
}

static real clamp(real v, real lo, real hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/* u = PTO(x1, x2): the regions in the reference's order (first match wins). */
double pto_u(double x1_in, double x2_in, const pto_params *p)
{
    const real x1 = (real)x1_in, x2 = (real)x2_in;
    const real a = (real)p->a, w = (real)p->w_max, d = (real)p->d;
    const int zone = p->omega0 > 0 && p->omega0 < p->w_max;
    const real om = zone ? (real)p->omega0 : w;
    real s;
    if (x1 == 0 && x2 == 0) {
        return 0.0; /* origin */
    }
    if (-d < x1 && x1 < d) { /* linear zone, eq. (34), saturated */
        return (double)clamp(-(real)p->k1 * x1 - (real)p->k2 * x2, -w, w);
    }
    s = sigma(x1, x2, a, w);
    if (zone) {
        if (x2 < 0 && s > 0 && sigma(x1, x2, a, om) <= 0) { /* S~_P and l1* */
            return (double)clamp(omega_c(x1, x2, a), om, w);
        }
        if (x2 > 0 && s < 0 && sigma(x1, x2, a, om) >= 0) { /* S~_N and l2* */
            return (double)-clamp(omega_c(x1, x2, a), om, w);
        }
    }
    if (s < 0 || (s == 0 && x2 < 0)) {
        return (double)w; /* S_P and l1 */
    }
    return (double)-w; /* S_N and l2 */
}
