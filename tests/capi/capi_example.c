/* The gmasim C API from C99 (ctest capi_c_example; docs/c_api.md): the built-in actuator at
 * 20 degC driven by the 10 Hz biased sine of Fig. 11 (-3 A to +5 A) for one period, 0.1 s,
 * sample by sample, as a real-time loop would; then the error paths and their codes.
 * Exit 0 when every check holds; each failed check prints one line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gmasim/capi/gmasim_c.h"

static int failures = 0;

#define CHECK(cond, ...)                                   \
  do {                                                     \
    if (!(cond)) {                                         \
      ++failures;                                          \
      fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__); \
      fprintf(stderr, __VA_ARGS__);                        \
      fprintf(stderr, "\n");                               \
    }                                                      \
  } while (0)

#define CHECK_STATUS(call, want)                                                             \
  do {                                                                                       \
    const int rc_ = (call);                                                                  \
    CHECK(rc_ == (want), "%s returned %s, expected %s (%s)", #call, gmasim_status_name(rc_), \
          gmasim_status_name(want), gmasim_last_error());                                    \
  } while (0)

static const double kPi = 3.14159265358979323846;

/* i(t) = min + pp/2 (1 - cos 2 pi f t): the biased sine of gmasim/simulate/simulate.hpp. */
static double biased_sine_A(double t_s) {
  const double min_A = -3.0, pp_A = 8.0, f_Hz = 10.0;
  return min_A + 0.5 * pp_A * (1.0 - cos(2.0 * kPi * f_Hz * t_s));
}

static void run_sine(const gmasim_model* model) {
  const double dt_s = 1e-5;
  const long steps = 10000; /* 0.1 s: one period */
  gmasim_sim* sim = NULL;
  double y_um = 0.0, y_min = 1e9, y_max = -1e9, B_min = 1e9, B_max = -1e9, t_s = 0.0;
  gmasim_outputs out;
  long k;
  int rods = 0, r;

  CHECK_STATUS(gmasim_sim_create(model, 20.0, dt_s, biased_sine_A(0.0), &sim), GMASIM_OK);
  if (!sim) return;
  for (k = 1; k <= steps; ++k) {
    const int rc = gmasim_sim_step(sim, biased_sine_A((double)k * dt_s));
    if (rc != GMASIM_OK) {
      CHECK(0, "step %ld: %s: %s", k, gmasim_status_name(rc), gmasim_sim_last_error(sim));
      break;
    }
    gmasim_sim_y_um(sim, &y_um);
    if (y_um < y_min) y_min = y_um;
    if (y_um > y_max) y_max = y_um;
    CHECK_STATUS(gmasim_sim_outputs(sim, &out), GMASIM_OK);
    if (out.B_T < B_min) B_min = out.B_T;
    if (out.B_T > B_max) B_max = out.B_T;
  }
  CHECK_STATUS(gmasim_sim_time_s(sim, &t_s), GMASIM_OK);
  CHECK(fabs(t_s - 0.1) < 1e-12, "t = %.15g s after %ld steps, expected 0.1 s", t_s, steps);
  printf(
      "10 Hz biased sine, -3..5 A, 20 degC, one period: stroke %.3f um (y %.3f..%.3f um), "
      "B %.4f..%.4f T\n",
      y_max - y_min, y_min, y_max, B_min, B_max);
  /* The MDMA prototype strokes tens of micrometres at 8 A peak-to-peak (Fig. 11-12). */
  CHECK(y_max - y_min > 10.0 && y_max - y_min < 200.0, "stroke %.3f um outside (10, 200) um",
        y_max - y_min);
  CHECK(B_max - B_min > 0.05 && B_max < 2.5 && B_min > -2.5, "B range %.4f..%.4f T", B_min, B_max);

  CHECK_STATUS(gmasim_sim_rod_count(sim, &rods), GMASIM_OK);
  CHECK(rods == 3, "rod count %d, expected 3", rods);
  for (r = 0; r < rods; ++r) {
    double F = 0.0, lambda = 0.0, M = 0.0;
    CHECK_STATUS(gmasim_sim_rod_force_N(sim, r, &F), GMASIM_OK);
    CHECK_STATUS(gmasim_sim_rod_strain(sim, r, &lambda), GMASIM_OK);
    CHECK_STATUS(gmasim_sim_rod_magnetisation_A_per_m(sim, r, &M), GMASIM_OK);
    CHECK(isfinite(F) && isfinite(lambda) && isfinite(M), "rod %d: F %g N, lambda %g, M %g A/m", r,
          F, lambda, M);
    CHECK(F == out.rod_F_N[r] && lambda == out.rod_strain[r] && M == out.rod_M_A_per_m[r],
          "rod %d: getters disagree with gmasim_sim_outputs", r);
  }
  gmasim_sim_free(sim);
}

static void error_paths(const gmasim_model* model) {
  gmasim_model* bad_model = NULL;
  gmasim_sim* sim = NULL;
  double v = 0.0;
  const double not_a_number = strtod("nan", NULL);

  CHECK_STATUS(gmasim_sim_step(NULL, 1.0), GMASIM_E_ARGUMENT);
  CHECK(strstr(gmasim_last_error(), "sim is NULL") != NULL, "message: %s", gmasim_last_error());
  CHECK_STATUS(gmasim_sim_y_um(NULL, &v), GMASIM_E_ARGUMENT);

  CHECK_STATUS(gmasim_model_load("no/such/model.toml", &bad_model), GMASIM_E_INPUT);
  CHECK(bad_model == NULL, "a failed load returned a handle");
  CHECK(strstr(gmasim_last_error(), "no/such/model.toml") != NULL,
        "the message does not name the file: %s", gmasim_last_error());

  CHECK_STATUS(gmasim_sim_create(model, 400.0, 1e-5, 0.0, &sim), GMASIM_E_INPUT);
  CHECK(strstr(gmasim_last_error(), "Curie") != NULL, "message: %s", gmasim_last_error());
  CHECK_STATUS(gmasim_sim_create(model, 20.0, 0.5, 0.0, &sim), GMASIM_E_INPUT);
  /* Issue 19, item 2: below GMASIM_MIN_DT_S (1e-29 s took y to 0; a denormal step gave
   * "nodal matrix = 0"). */
  CHECK_STATUS(gmasim_sim_create(model, 20.0, 1e-29, 0.0, &sim), GMASIM_E_INPUT);
  CHECK(strstr(gmasim_last_error(), "must be >= 1e-12 s") != NULL, "message: %s",
        gmasim_last_error());
  CHECK_STATUS(gmasim_sim_create(model, 20.0, 4.9e-324, 0.0, &sim), GMASIM_E_INPUT);
  CHECK_STATUS(gmasim_sim_create(model, 20.0, GMASIM_MIN_DT_S, 0.0, &sim), GMASIM_OK);
  gmasim_sim_free(sim);
  sim = NULL;
  CHECK_STATUS(gmasim_sim_create(model, 20.0, 1e-5, 0.0, &sim), GMASIM_OK);
  if (!sim) return;
  CHECK_STATUS(gmasim_sim_step(sim, not_a_number), GMASIM_E_ARGUMENT);
  CHECK(strstr(gmasim_sim_last_error(sim), "finite") != NULL, "message: %s",
        gmasim_sim_last_error(sim));
  CHECK_STATUS(gmasim_sim_step(sim, 5000.0), GMASIM_E_INPUT);
  CHECK_STATUS(gmasim_sim_rod_force_N(sim, 3, &v), GMASIM_E_ARGUMENT);
  CHECK_STATUS(gmasim_sim_set_temperature(sim, 380.0), GMASIM_E_INPUT);
  CHECK_STATUS(gmasim_sim_set_temperature(sim, 70.0), GMASIM_OK);
  CHECK_STATUS(gmasim_sim_step(sim, 1.0), GMASIM_OK);
  CHECK_STATUS(gmasim_sim_reset(sim, 0.0), GMASIM_OK);
  gmasim_sim_free(sim);
}

/* Ownership (issue 19, item 12): a freed, foreign or forged handle is an error code, never
 * undefined behaviour. Under the sanitizer build nothing here may read freed memory. */
static void handle_rules(void) {
  gmasim_model* model = NULL;
  gmasim_model* again = NULL;
  gmasim_sim* sim = NULL;
  double y = 0.0;
  int rods = 0;

  CHECK_STATUS(gmasim_model_load(NULL, &model), GMASIM_OK);
  if (!model) return;
  CHECK_STATUS(gmasim_sim_create(model, 20.0, 1e-5, 0.0, &sim), GMASIM_OK);
  if (!sim) return;
  /* A sim's handle is not a model's, and the reverse. */
  CHECK_STATUS(gmasim_model_rod_count((const gmasim_model*)(const void*)sim, &rods),
               GMASIM_E_ARGUMENT);
  CHECK(strstr(gmasim_last_error(), "not a live gmasim_model handle") != NULL, "message: %s",
        gmasim_last_error());
  CHECK_STATUS(gmasim_sim_step((gmasim_sim*)(void*)model, 1.0), GMASIM_E_ARGUMENT);
  /* The model may go first: the sim keeps what it needs. */
  CHECK_STATUS(gmasim_model_free(model), GMASIM_OK);
  CHECK_STATUS(gmasim_model_free(model), GMASIM_E_ARGUMENT); /* a double free */
  CHECK(strstr(gmasim_last_error(), "gmasim_model_free: model = ") != NULL &&
            strstr(gmasim_last_error(), "freed already") != NULL,
        "message: %s", gmasim_last_error());
  CHECK_STATUS(gmasim_model_rod_count(model, &rods), GMASIM_E_ARGUMENT); /* use after free */
  CHECK(strstr(gmasim_model_last_error(model), "not a live") != NULL, "message: %s",
        gmasim_model_last_error(model));
  CHECK_STATUS(gmasim_sim_create(model, 20.0, 1e-5, 0.0, &sim), GMASIM_E_ARGUMENT);
  CHECK(sim == NULL, "a refused create returned a handle");
  /* A new model may reuse the slot; the old handle stays dead. */
  CHECK_STATUS(gmasim_model_load(NULL, &again), GMASIM_OK);
  CHECK(again != model, "a freed handle came back as a new one");
  CHECK_STATUS(gmasim_model_rod_count(model, &rods), GMASIM_E_ARGUMENT);
  CHECK_STATUS(gmasim_model_rod_count(again, &rods), GMASIM_OK);
  CHECK_STATUS(gmasim_sim_create(again, 20.0, 1e-5, 0.0, &sim), GMASIM_OK);
  CHECK_STATUS(gmasim_sim_step(sim, 1.0), GMASIM_OK);
  CHECK_STATUS(gmasim_sim_free(sim), GMASIM_OK);
  CHECK_STATUS(gmasim_sim_step(sim, 1.0), GMASIM_E_ARGUMENT);
  CHECK_STATUS(gmasim_sim_y_um(sim, &y), GMASIM_E_ARGUMENT);
  CHECK_STATUS(gmasim_sim_free(sim), GMASIM_E_ARGUMENT);
  CHECK(strstr(gmasim_sim_last_error(sim), "not a live gmasim_sim handle") != NULL, "message: %s",
        gmasim_sim_last_error(sim));
  /* A value the API never returned. */
  CHECK_STATUS(gmasim_sim_free((gmasim_sim*)(void*)&y), GMASIM_E_ARGUMENT);
  CHECK_STATUS(gmasim_model_free(again), GMASIM_OK);
  CHECK_STATUS(gmasim_model_free(NULL), GMASIM_OK);
  CHECK_STATUS(gmasim_sim_free(NULL), GMASIM_OK);
}

int main(void) {
  gmasim_model* model = NULL;
  printf("gmasim %s%s%s\n", gmasim_version(), gmasim_git_describe()[0] ? " " : "",
         gmasim_git_describe());
  CHECK_STATUS(gmasim_model_load(NULL, &model), GMASIM_OK);
  if (!model) return 1;
  run_sine(model);
  error_paths(model);
  handle_rules();
  CHECK_STATUS(gmasim_model_free(model), GMASIM_OK);
  if (failures)
    fprintf(stderr, "%d check(s) failed\n", failures);
  else
    printf("all checks passed\n");
  return failures ? 1 : 0;
}
