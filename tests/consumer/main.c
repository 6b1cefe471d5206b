/* The C API from an install prefix: the same 100 steps as main.cpp through libgmasim_c.so. */
#include <stdio.h>

/* The old flat path (a forwarding header) and the new one, together. */
#include "gmasim/capi/gmasim_c.h"
#include "gmasim/gmasim_c.h"

int main(void) {
  gmasim_model* model = NULL;
  gmasim_sim* sim = NULL;
  double y_m = 0.0;
  int k;
  if (gmasim_model_load(NULL, &model) != GMASIM_OK ||
      gmasim_sim_create(model, 20.0, 1e-5, 0.0, &sim) != GMASIM_OK) {
    fprintf(stderr, "consumer_c: %s\n", gmasim_last_error());
    gmasim_model_free(model);
    return 1;
  }
  for (k = 1; k <= 100; ++k) {
    if (gmasim_sim_step(sim, 0.05 * k) != GMASIM_OK) {
      fprintf(stderr, "consumer_c: %s\n", gmasim_sim_last_error(sim));
      return 1;
    }
  }
  gmasim_sim_y_m(sim, &y_m);
  printf("C gmasim %s: y_m %.17g\n", gmasim_version(), y_m);
  gmasim_sim_free(sim);
  gmasim_model_free(model);
  return y_m > 0.0 ? 0 : 1;
}
