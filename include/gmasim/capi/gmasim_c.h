/* gmasim C API: a giant magnetostrictive actuator stepped sample by sample from C, C++,
 * Python ctypes or any language with a C FFI (docs/c_api.md).
 *
 * Pure C (C99 and later, and C++): opaque handles, plain doubles and ints, no C++ types.
 * Units are SI and named in every function: _s seconds, _A amperes, _C degrees Celsius,
 * _m metres, _um micrometres, _T tesla, _N newtons, _A_per_m amperes per metre.
 *
 * Errors: every function that can fail returns an int status (enum gmasim_status); nothing
 * else is written when it fails, and no C++ exception ever crosses this boundary. The message
 * of the failure is kept per handle (gmasim_model_last_error, gmasim_sim_last_error) and per
 * thread (gmasim_last_error: the last failed call of this thread, the only place to read why a
 * create or load failed). Messages name the function, the value and the rule.
 *
 * Real time: gmasim_sim_step and every getter allocate nothing and take no lock; a step is
 * deterministic (same inputs, same bits). Creation, load, reset and set_temperature allocate.
 * A handle is not thread-safe; different sims may be used from different threads at once,
 * and one model may feed sims in several threads (a sim keeps its model alive, so the model
 * handle may be freed before the sims made from it).
 *
 * Ownership (docs/c_api.md, "Handles"): the caller owns every handle a create or load returns
 * and frees it exactly once with its _free function. A handle is a generation-counted token,
 * not an address: after its free, the same value (a double free, a use after free), a handle
 * of the other type, or any value the API did not return is refused with GMASIM_E_ARGUMENT
 * ("not a live ... handle"); nothing is read through it. Freeing a handle while another
 * thread uses it is the caller's race.
 */
#ifndef GMASIM_GMASIM_C_H
#define GMASIM_GMASIM_C_H

#if defined(__GNUC__) || defined(__clang__)
#define GMASIM_API __attribute__((visibility("default")))
#else
#define GMASIM_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes returned by every function that can fail. */
enum gmasim_status {
  GMASIM_OK = 0,
  GMASIM_E_INPUT = 1,    /* a bad model file, a temperature at/above the Curie point, a current
                            or time step out of range, ...: the message names value and rule */
  GMASIM_E_DIVERGED = 2, /* the step diverged (the message names time, rod and quantity); the
                            sim refuses further steps until gmasim_sim_reset */
  GMASIM_E_ARGUMENT = 3, /* a NULL handle or output pointer, a handle that is not live (freed
                            already, or never returned by the API), a rod index out of range,
                            or a non-finite number (NaN, +-Inf) */
  GMASIM_E_INTERNAL = 4  /* out of memory or a bug: the message says what */
};

/* Rods a model may have (stack.rods): the size of the per-rod arrays of gmasim_outputs. */
#define GMASIM_MAX_RODS 8

/* Time steps a sim accepts [s]: GMASIM_MIN_DT_S <= dt_s <= GMASIM_MAX_DT_S. Below the minimum
 * the step no longer holds the state at constant current (docs/model.md, "Time step"). */
#define GMASIM_MIN_DT_S 1e-12
#define GMASIM_MAX_DT_S 1e-3
/* Largest coil current magnitude [A] (kMaxCurrent_A of gmasim/simulate/simulate.hpp). */
#define GMASIM_MAX_CURRENT_A 1000.0

typedef struct gmasim_model gmasim_model; /* a compiled, immutable model */
typedef struct gmasim_sim gmasim_sim;     /* model + conditions at one temperature + state */

/* Everything a sim reports after its last step (or creation/reset), in SI units. Per-rod
 * entries at and beyond rod_count are 0. */
typedef struct gmasim_outputs {
  double t_s;                 /* time since creation/reset [s] = steps * dt_s */
  double dt_s;                /* the sim's time step [s] */
  double current_A;           /* coil current at t_s [A] */
  double temperature_C;       /* operating temperature [degC] */
  double y_m;                 /* output displacement the sensor reads [m] */
  double y_um;                /* the same [um] (y_m * 1e6) */
  double y_stack_m;           /* rod stack output x1 + x2 + ... (eq. 20) [m] */
  double B_T;                 /* flux density seen by the induction coil [T] */
  double thermal_expansion_m; /* eq. (21) thermal expansion of the stack at temperature_C [m] */
  long steps;                 /* steps taken since creation/reset */
  int rod_count;              /* rods of the model (<= GMASIM_MAX_RODS) */
  int diverged;               /* 1 after a divergence until reset, else 0 */
  double rod_F_N[GMASIM_MAX_RODS];       /* rod force [N] */
  double rod_strain[GMASIM_MAX_RODS];    /* magnetostrictive strain lambda of eq. (11) [-] */
  double rod_M_A_per_m[GMASIM_MAX_RODS]; /* magnetisation M [A/m] */
  double rod_H_A_per_m[GMASIM_MAX_RODS]; /* field H [A/m] */
  double rod_B_T[GMASIM_MAX_RODS];       /* flux density phi/A the circuit assigns the rod [T] */
  double rod_x_m[GMASIM_MAX_RODS];       /* rod displacement [m] */
  double rod_E_Pa[GMASIM_MAX_RODS];      /* Young's modulus E_G of eq. (13) [Pa] */
  double rod_mu_r[GMASIM_MAX_RODS];      /* relative permeability [-] */
} gmasim_outputs;

/* ---- library ------------------------------------------------------------------------- */

/* The library version, "MAJOR.MINOR.PATCH" (e.g. "0.1.0"). Never NULL; static storage. */
GMASIM_API const char* gmasim_version(void);
/* `git describe` of the source tree at configure time, or "" when it was not a git checkout.
 * Never NULL; static storage. */
GMASIM_API const char* gmasim_git_describe(void);
/* The name of a status code ("GMASIM_OK", "GMASIM_E_INPUT", ...; "unknown status" otherwise).
 * Never NULL; static storage. */
GMASIM_API const char* gmasim_status_name(int status);
/* The message of the last failed call made by this thread, "" if none failed yet. Never NULL;
 * valid until this thread's next failed call. */
GMASIM_API const char* gmasim_last_error(void);

/* ---- model --------------------------------------------------------------------------- */

/* Loads and compiles a TOML model file (docs/model.md, "Model file"); path NULL or "" loads
 * the built-in MDMA model. On success *out is a new handle (free it with gmasim_model_free).
 * GMASIM_E_INPUT if the file cannot be read or breaks the schema (the message names the file
 * and line), GMASIM_E_ARGUMENT if out is NULL. Allocates. */
GMASIM_API int gmasim_model_load(const char* path, gmasim_model** out);
/* The same from the TOML text itself (NUL-terminated); source_name (NULL or "" for
 * "<string>") names it in messages. */
GMASIM_API int gmasim_model_load_string(const char* toml_text, const char* source_name,
                                        gmasim_model** out);
/* Frees a model handle: GMASIM_OK (NULL is ignored), or GMASIM_E_ARGUMENT if the handle is not
 * live (freed already: a double free is an error code, not undefined behaviour). Sims created
 * from it stay valid. */
GMASIM_API int gmasim_model_free(gmasim_model* model);
/* The message of the last failed call on this model handle, "" if none; "" for NULL; a static
 * "not a live gmasim_model handle ..." for a freed or unknown handle. */
GMASIM_API const char* gmasim_model_last_error(const gmasim_model* model);
/* The number of rods of the model (1..GMASIM_MAX_RODS). */
GMASIM_API int gmasim_model_rod_count(const gmasim_model* model, int* out);
/* The name of rod `rod` (0-based, "rod1", ...): valid while the model handle lives. */
GMASIM_API int gmasim_model_rod_name(const gmasim_model* model, int rod, const char** out);

/* ---- sim ----------------------------------------------------------------------------- */

/* A new sim of `model` at temperature_C [degC] (below the model's Curie point, above absolute
 * zero), at rest under current_A [A] (|current_A| <= GMASIM_MAX_CURRENT_A), stepped by dt_s
 * [s] (GMASIM_MIN_DT_S <= dt_s <= GMASIM_MAX_DT_S). t = 0. Free it with gmasim_sim_free.
 * GMASIM_E_ARGUMENT for a NULL model/out or a non-finite number, GMASIM_E_INPUT for a value out of
 * range, GMASIM_E_DIVERGED if no initial equilibrium is found. Allocates. */
GMASIM_API int gmasim_sim_create(const gmasim_model* model, double temperature_C, double dt_s,
                                 double current_A, gmasim_sim** out);
/* Frees a sim: GMASIM_OK (NULL is ignored), or GMASIM_E_ARGUMENT if the handle is not live. */
GMASIM_API int gmasim_sim_free(gmasim_sim* sim);
/* The message of the last failed call on this sim, "" if none; "" for NULL; a static text for a
 * freed or unknown handle. Valid until the next failed call on the sim. */
GMASIM_API const char* gmasim_sim_last_error(const gmasim_sim* sim);

/* Back to t = 0, at rest under current_A [A], at the sim's present temperature; clears a
 * divergence. Allocates. On failure the sim is unchanged. */
GMASIM_API int gmasim_sim_reset(gmasim_sim* sim, double current_A);
/* Advances the sim by one step of its dt_s; current_A [A] is the coil current at the end of
 * the step (|current_A| <= GMASIM_MAX_CURRENT_A). Allocation-free and deterministic.
 * GMASIM_E_ARGUMENT (NaN/Inf) and GMASIM_E_INPUT (too large) leave the sim untouched;
 * GMASIM_E_DIVERGED stops it: every further step returns GMASIM_E_DIVERGED until
 * gmasim_sim_reset. */
GMASIM_API int gmasim_sim_step(gmasim_sim* sim, double current_A);
/* Recomputes every temperature-dependent constant at temperature_C [degC] and keeps the
 * state, t and steps (a temperature change between two steps). NOT allocation-free: call it
 * outside a hard real-time loop. On failure (e.g. at/above the Curie point) the sim is
 * unchanged. */
GMASIM_API int gmasim_sim_set_temperature(gmasim_sim* sim, double temperature_C);

/* Getters: allocation-free; each writes *out and returns GMASIM_OK, or GMASIM_E_ARGUMENT for a
 * NULL sim/out or a rod index outside [0, rod count). Values after the last step (or
 * creation/reset). */
GMASIM_API int gmasim_sim_time_s(const gmasim_sim* sim, double* out);        /* t [s] */
GMASIM_API int gmasim_sim_dt_s(const gmasim_sim* sim, double* out);          /* dt [s] */
GMASIM_API int gmasim_sim_steps(const gmasim_sim* sim, long* out);           /* steps taken */
GMASIM_API int gmasim_sim_current_A(const gmasim_sim* sim, double* out);     /* coil [A] */
GMASIM_API int gmasim_sim_temperature_C(const gmasim_sim* sim, double* out); /* [degC] */
GMASIM_API int gmasim_sim_y_m(const gmasim_sim* sim, double* out);           /* output [m] */
GMASIM_API int gmasim_sim_y_um(const gmasim_sim* sim, double* out);          /* output [um] */
GMASIM_API int gmasim_sim_B_T(const gmasim_sim* sim, double* out);   /* coil flux density [T] */
GMASIM_API int gmasim_sim_diverged(const gmasim_sim* sim, int* out); /* 1 if stopped, else 0 */
GMASIM_API int gmasim_sim_rod_count(const gmasim_sim* sim, int* out);
GMASIM_API int gmasim_sim_rod_force_N(const gmasim_sim* sim, int rod, double* out); /* [N] */
/* Magnetostrictive strain lambda of eq. (11) [-] (dimensionless; 1e-6 = 1 ppm). */
GMASIM_API int gmasim_sim_rod_strain(const gmasim_sim* sim, int rod, double* out);
GMASIM_API int gmasim_sim_rod_magnetisation_A_per_m(const gmasim_sim* sim, int rod,
                                                    double* out); /* M [A/m] */
/* Fills every field of *out at once. */
GMASIM_API int gmasim_sim_outputs(const gmasim_sim* sim, gmasim_outputs* out);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* GMASIM_GMASIM_C_H */
