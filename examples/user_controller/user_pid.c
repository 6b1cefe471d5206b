/* Your controller in the loop through the C API (docs/experiments.md, "Your controller in the
 * loop"): the paper's discrete PID (Fig. 16; the gains of gmasim track) written by hand around
 * gmasim_sim, tracking y_bias + A sin(2 pi f t) at one temperature -- the loop a lab would run
 * on its real-time target, with the actuator model in place of the hardware.
 *
 *   user_pid [temperature_C] [amplitude_um] [frequency_Hz]     (default 20 10 10)
 *
 * The loop is gmasim track's, sample for sample: a 10 kHz controller, the plant stepped 10 times
 * per sample (dt = 10 us), the sensor read at the sample instant, the current held until the
 * next; the RMS error over the last of 4 periods, at every plant step. It prints one JSON line;
 * python/tests/test_controller.py checks that it equals `gmasim track`'s error to the last bit.
 * Exit 0, or 1 with the C API's message. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gmasim/capi/gmasim_c.h"

static const double kPi = 3.14159265358979323846;

/* The PID of gmasim track (include/gmasim/experiments/experiments.hpp, class Pid): positional,
 * conditional-integration anti-windup, the gains per sample at the 10 kHz reference rate. */
typedef struct {
  double kp, ki, kd;   /* per sample [unit/um] */
  double u_min, u_max; /* output limits [unit] */
  double sum, e_prev;
  int first;
} pid_t_;

static double pid_update(pid_t_* c, double e) {
  const double de = c->first ? 0.0 : e - c->e_prev;
  const double sum_new = c->sum + e;
  const double u_raw = c->kp * e + c->ki * sum_new + c->kd * de;
  double u = u_raw;
  c->first = 0;
  c->e_prev = e;
  if (u_raw > c->u_max) u = c->u_max;
  if (u_raw < c->u_min) u = c->u_min;
  if (!((u_raw > c->u_max && e > 0.0) || (u_raw < c->u_min && e < 0.0))) c->sum = sum_new;
  return u;
}

static int fail(const char* what, gmasim_sim* sim) {
  fprintf(stderr, "user_pid: %s: %s\n", what,
          sim ? gmasim_sim_last_error(sim) : gmasim_last_error());
  return 1;
}

int main(int argc, char** argv) {
  const double T_C = argc > 1 ? atof(argv[1]) : 20.0;
  const double A_um = argc > 2 ? atof(argv[2]) : 10.0;
  const double f_Hz = argc > 3 ? atof(argv[3]) : 10.0;
  const double fs_Hz = 10000.0, Ts = 1.0 / fs_Hz, periods = 4.0;
  const long sub = 10; /* plant steps per sample: dt = 10 us (gmasim track's rule at 10 Hz) */
  const double dt_s = Ts / (double)sub;
  const double bias_A = 1.0, limit_A = 10.0, amplifier_A_per_unit = 0.5;
  const double period_s = 1.0 / f_Hz, w_rad_per_s = 2.0 * kPi * f_Hz;
  const long samples = lround(periods * period_s / Ts);
  const double t_end = (double)samples * Ts, after_s = (t_end - period_s) + 1e-12 * period_s;
  pid_t_ pid = {0.2, 0.03 * 10000.0 / fs_Hz, 0.007 * fs_Hz / 10000.0, 0, 0, 0.0, 0.0, 1};
  gmasim_model* model = NULL;
  gmasim_sim* sim = NULL;
  double y_bias_um = 0.0, y_um = 0.0, ss = 0.0;
  long j, q, n = 0;

  pid.u_min = (-limit_A - bias_A) / amplifier_A_per_unit;
  pid.u_max = (limit_A - bias_A) / amplifier_A_per_unit;
  if (gmasim_model_load(NULL, &model) != GMASIM_OK) return fail("model", NULL);
  if (gmasim_sim_create(model, T_C, dt_s, bias_A, &sim) != GMASIM_OK) return fail("sim", NULL);
  gmasim_sim_y_um(sim, &y_bias_um); /* the operating point the reference is centred on */
  for (j = 0; j < samples; ++j) {
    const double tk = (double)j * Ts;
    double e, current_A;
    gmasim_sim_y_um(sim, &y_um); /* the sensor at the sample instant */
    e = y_bias_um + A_um * sin(w_rad_per_s * tk) - y_um;
    current_A = bias_A + amplifier_A_per_unit * pid_update(&pid, e);
    for (q = 1; q <= sub; ++q) {
      const double t = tk + (double)q * dt_s;
      double err;
      if (gmasim_sim_step(sim, current_A) != GMASIM_OK) return fail("step", sim);
      gmasim_sim_y_um(sim, &y_um);
      err = y_bias_um + A_um * sin(w_rad_per_s * t) - y_um;
      if (t > after_s) {
        ss += err * err;
        ++n;
      }
    }
  }
  printf(
      "{\"temperature_C\": %.17g, \"amplitude_um\": %.17g, \"frequency_Hz\": %.17g, "
      "\"y_bias_um\": %.17g, \"error_rms_um\": %.17g}\n",
      T_C, A_um, f_Hz, y_bias_um, sqrt(ss / (double)(n > 0 ? n : 1)));
  gmasim_sim_free(sim);
  gmasim_model_free(model);
  return 0;
}
