// The C API (gmasim/capi/gmasim_c.h) over gmasim::Stepper: status codes instead of exceptions,
// error messages in fixed buffers (setting one allocates nothing), no exception crosses the
// boundary, and generation-counted handles (capi/handles.hpp): a freed or unknown handle is an
// error code.
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <exception>
#include <memory>
#include <new>
#include <string>

#include "gmasim/capi/gmasim_c.h"
#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/simulate/simulate.hpp"
#include "gmasim/simulate/stepper.hpp"
#include "gmasim/version.h"
#include "handles.hpp"  // src/capi/, beside this file

static_assert(GMASIM_MAX_DT_S == gmasim::kMaxStepperDt_s, "gmasim_c.h: GMASIM_MAX_DT_S");
static_assert(GMASIM_MIN_DT_S == gmasim::kMinStepDt_s, "gmasim_c.h: GMASIM_MIN_DT_S");
static_assert(GMASIM_MAX_CURRENT_A == gmasim::kMaxCurrent_A, "gmasim_c.h: GMASIM_MAX_CURRENT_A");

namespace {

// Room for a clipped library message (kMaxErrorChars) and the function name before it.
constexpr std::size_t kErrorBuffer = gmasim::kMaxErrorChars + 512;

struct ErrorText {
  char text[kErrorBuffer] = {};
};

thread_local ErrorText t_last_error;

}  // namespace

namespace {

// What a handle stands for. gmasim_model and gmasim_sim themselves stay incomplete types: a
// handle is a value of the tables below, never the address of one of these.
struct ModelObject {
  std::shared_ptr<const gmasim::Model> model;
  mutable ErrorText error;
};

struct SimObject {
  gmasim::Stepper stepper;
  mutable ErrorText error;
};

using ModelTable = gmasim::capi_detail::HandleTable<ModelObject, 1>;
using SimTable = gmasim::capi_detail::HandleTable<SimObject, 2>;

// Never destroyed: a handle freed by a static destructor of the program after ours ran must
// still find its table.
ModelTable& models() {
  static ModelTable* t = new ModelTable;
  return *t;
}
SimTable& sims() {
  static SimTable* t = new SimTable;
  return *t;
}

std::uintptr_t value_of(const void* h) { return reinterpret_cast<std::uintptr_t>(h); }
const ModelObject* object_of(const gmasim_model* h) { return models().get(value_of(h)); }
SimObject* object_of(const gmasim_sim* h) { return sims().get(value_of(h)); }
gmasim_model* model_handle(std::uintptr_t v) { return reinterpret_cast<gmasim_model*>(v); }
gmasim_sim* sim_handle(std::uintptr_t v) { return reinterpret_cast<gmasim_sim*>(v); }

// Text of a handle that is no live handle (static storage).
constexpr const char* kDeadModel =
    "not a live gmasim_model handle (freed already, or not made by gmasim_model_load*)";
constexpr const char* kDeadSim =
    "not a live gmasim_sim handle (freed already, or not made by gmasim_sim_create)";

// Writes "<fn>: <message>" into the thread's buffer and, if given, the handle's.
void set_error(ErrorText* handle, const char* fn, const char* format, ...)
    __attribute__((format(printf, 3, 4)));
void set_error(ErrorText* handle, const char* fn, const char* format, ...) {
  char* t = t_last_error.text;
  const int n = std::snprintf(t, kErrorBuffer, "%s: ", fn);
  if (n >= 0 && static_cast<std::size_t>(n) < kErrorBuffer) {
    va_list args;
    va_start(args, format);
    std::vsnprintf(t + n, kErrorBuffer - static_cast<std::size_t>(n), format, args);
    va_end(args);
  }
  if (handle) std::snprintf(handle->text, kErrorBuffer, "%s", t);
}

ErrorText* error_of(const ModelObject* m) { return m ? &m->error : nullptr; }
ErrorText* error_of(const SimObject* s) { return s ? &s->error : nullptr; }

// Runs f() and turns every exception into a status code and a message.
template <class Object, class F>
int guarded(const Object* h, const char* fn, F&& f) noexcept {
  try {
    return f();
  } catch (const gmasim::InputError& e) {
    set_error(error_of(h), fn, "%s", e.what());
    return GMASIM_E_INPUT;
  } catch (const gmasim::DivergenceError& e) {
    set_error(error_of(h), fn, "%s", e.what());
    return GMASIM_E_DIVERGED;
  } catch (const std::bad_alloc&) {
    set_error(error_of(h), fn, "out of memory");
    return GMASIM_E_INTERNAL;
  } catch (const std::exception& e) {
    set_error(error_of(h), fn, "internal error: %s", e.what());
    return GMASIM_E_INTERNAL;
  } catch (...) {
    set_error(error_of(h), fn, "internal error: unknown exception");
    return GMASIM_E_INTERNAL;
  }
}

template <class Object>
int null_argument(const Object* h, const char* fn, const char* what) {
  set_error(error_of(h), fn, "%s is NULL", what);
  return GMASIM_E_ARGUMENT;
}

// A handle argument that is NULL or no live handle: GMASIM_E_ARGUMENT, with the message in the
// thread's buffer only (a dead handle has no buffer of its own).
int bad_handle(const void* h, const char* fn, const char* what, const char* dead) {
  if (!h) return null_argument<ModelObject>(nullptr, fn, what);
  set_error(nullptr, fn, "%s = %p: %s", what, h, dead);
  return GMASIM_E_ARGUMENT;
}

// A finite number, else GMASIM_E_ARGUMENT naming it.
int check_finite(const SimObject* h, const char* fn, const char* what, const char* unit, double v) {
  if (std::isfinite(v)) return GMASIM_OK;
  set_error(error_of(h), fn, "%s = %g %s: must be a finite number", what, v, unit);
  return GMASIM_E_ARGUMENT;
}

int check_rod(const SimObject* s, const char* fn, int rod) {
  const int n = s->stepper.rod_count();
  if (rod >= 0 && rod < n) return GMASIM_OK;
  set_error(error_of(s), fn, "rod index %d: out of range [0, %d) (the model has %d rods)", rod, n,
            n);
  return GMASIM_E_ARGUMENT;
}

// Getter boilerplate: a live sim, out non-NULL, then *out = value(stepper).
template <class T, class F>
int get(const gmasim_sim* h, T* out, const char* fn, F&& value) {
  const SimObject* s = object_of(h);
  if (!s) return bad_handle(h, fn, "sim", kDeadSim);
  if (!out) return null_argument(s, fn, "out");
  *out = value(s->stepper);
  return GMASIM_OK;
}

template <class F>
int get_rod(const gmasim_sim* h, int rod, double* out, const char* fn, F&& value) {
  const SimObject* s = object_of(h);
  if (!s) return bad_handle(h, fn, "sim", kDeadSim);
  if (!out) return null_argument(s, fn, "out");
  if (const int rc = check_rod(s, fn, rod)) return rc;
  *out = value(s->stepper.state().rods[static_cast<std::size_t>(rod)]);
  return GMASIM_OK;
}

int load(std::shared_ptr<const gmasim::Model> (*make)(const char*, const char*), const char* a,
         const char* b, gmasim_model** out, const char* fn) {
  if (!out) return null_argument<ModelObject>(nullptr, fn, "out");
  *out = nullptr;
  return guarded<ModelObject>(nullptr, fn, [&] {
    auto h = std::make_unique<ModelObject>();
    h->model = make(a, b);
    *out = model_handle(models().add(std::move(h)));
    return GMASIM_OK;
  });
}

// Frees a handle of `table`: NULL is ignored (GMASIM_OK); a dead handle is GMASIM_E_ARGUMENT.
template <class Table>
int free_handle(Table& table, const void* h, const char* fn, const char* what, const char* dead) {
  if (!h) return GMASIM_OK;
  if (table.remove(value_of(h))) return GMASIM_OK;
  return bad_handle(h, fn, what, dead);
}

}  // namespace

extern "C" {

const char* gmasim_version(void) { return GMASIM_VERSION; }

const char* gmasim_git_describe(void) { return GMASIM_GIT_DESCRIBE; }

const char* gmasim_status_name(int status) {
  switch (status) {
    case GMASIM_OK:
      return "GMASIM_OK";
    case GMASIM_E_INPUT:
      return "GMASIM_E_INPUT";
    case GMASIM_E_DIVERGED:
      return "GMASIM_E_DIVERGED";
    case GMASIM_E_ARGUMENT:
      return "GMASIM_E_ARGUMENT";
    case GMASIM_E_INTERNAL:
      return "GMASIM_E_INTERNAL";
    default:
      return "unknown status";
  }
}

const char* gmasim_last_error(void) { return t_last_error.text; }

// ---- model ------------------------------------------------------------------------------

int gmasim_model_load(const char* path, gmasim_model** out) {
  return load(
      [](const char* p, const char*) -> std::shared_ptr<const gmasim::Model> {
        return std::make_shared<const gmasim::Model>(gmasim::load_model(p ? p : ""));
      },
      path, nullptr, out, "gmasim_model_load");
}

int gmasim_model_load_string(const char* toml_text, const char* source_name, gmasim_model** out) {
  const char* fn = "gmasim_model_load_string";
  if (!toml_text) return null_argument<ModelObject>(nullptr, fn, "toml_text");
  return load(
      [](const char* text, const char* name) -> std::shared_ptr<const gmasim::Model> {
        const std::string source = name && *name ? name : "<string>";
        return std::make_shared<const gmasim::Model>(
            gmasim::compile(gmasim::parse_model_spec(text, source)));
      },
      toml_text, source_name, out, fn);
}

int gmasim_model_free(gmasim_model* model) {
  return free_handle(models(), model, "gmasim_model_free", "model", kDeadModel);
}

const char* gmasim_model_last_error(const gmasim_model* model) {
  if (!model) return "";
  const ModelObject* m = object_of(model);
  return m ? m->error.text : kDeadModel;
}

int gmasim_model_rod_count(const gmasim_model* model, int* out) {
  const char* fn = "gmasim_model_rod_count";
  const ModelObject* m = object_of(model);
  if (!m) return bad_handle(model, fn, "model", kDeadModel);
  if (!out) return null_argument(m, fn, "out");
  *out = m->model->rod_count();
  return GMASIM_OK;
}

int gmasim_model_rod_name(const gmasim_model* model, int rod, const char** out) {
  const char* fn = "gmasim_model_rod_name";
  const ModelObject* m = object_of(model);
  if (!m) return bad_handle(model, fn, "model", kDeadModel);
  if (!out) return null_argument(m, fn, "out");
  const int n = m->model->rod_count();
  if (rod < 0 || rod >= n) {
    set_error(&m->error, fn, "rod index %d: out of range [0, %d) (the model has %d rods)", rod, n,
              n);
    return GMASIM_E_ARGUMENT;
  }
  *out = m->model->rods[static_cast<std::size_t>(rod)].name.c_str();
  return GMASIM_OK;
}

// ---- sim --------------------------------------------------------------------------------

int gmasim_sim_create(const gmasim_model* model, double temperature_C, double dt_s,
                      double current_A, gmasim_sim** out) {
  const char* fn = "gmasim_sim_create";
  if (!out) return null_argument<SimObject>(nullptr, fn, "out");
  *out = nullptr;
  const ModelObject* m = object_of(model);
  if (!m) return bad_handle(model, fn, "model", kDeadModel);
  if (int rc = check_finite(nullptr, fn, "temperature", "degC", temperature_C)) return rc;
  if (int rc = check_finite(nullptr, fn, "time step dt", "s", dt_s)) return rc;
  if (int rc = check_finite(nullptr, fn, "coil current", "A", current_A)) return rc;
  return guarded<SimObject>(nullptr, fn, [&] {
    auto h = std::unique_ptr<SimObject>(
        new SimObject{gmasim::Stepper(m->model, temperature_C, dt_s, current_A), {}});
    *out = sim_handle(sims().add(std::move(h)));
    return GMASIM_OK;
  });
}

int gmasim_sim_free(gmasim_sim* sim) {
  return free_handle(sims(), sim, "gmasim_sim_free", "sim", kDeadSim);
}

const char* gmasim_sim_last_error(const gmasim_sim* sim) {
  if (!sim) return "";
  const SimObject* s = object_of(sim);
  return s ? s->error.text : kDeadSim;
}

int gmasim_sim_reset(gmasim_sim* sim, double current_A) {
  const char* fn = "gmasim_sim_reset";
  SimObject* s = object_of(sim);
  if (!s) return bad_handle(sim, fn, "sim", kDeadSim);
  if (int rc = check_finite(s, fn, "coil current", "A", current_A)) return rc;
  return guarded(s, fn, [&] {
    s->stepper.reset(current_A);
    return GMASIM_OK;
  });
}

int gmasim_sim_step(gmasim_sim* sim, double current_A) {
  const char* fn = "gmasim_sim_step";
  SimObject* s = object_of(sim);
  if (!s) return bad_handle(sim, fn, "sim", kDeadSim);
  if (int rc = check_finite(s, fn, "coil current", "A", current_A)) return rc;
  if (s->stepper.diverged()) {
    set_error(&s->error, fn,
              "refused: the sim diverged earlier (%s); call gmasim_sim_reset before stepping "
              "again",
              s->stepper.divergence_message().c_str());
    return GMASIM_E_DIVERGED;
  }
  return guarded(s, fn, [&] {
    s->stepper.step(current_A);
    return GMASIM_OK;
  });
}

int gmasim_sim_set_temperature(gmasim_sim* sim, double temperature_C) {
  const char* fn = "gmasim_sim_set_temperature";
  SimObject* s = object_of(sim);
  if (!s) return bad_handle(sim, fn, "sim", kDeadSim);
  if (int rc = check_finite(s, fn, "temperature", "degC", temperature_C)) return rc;
  return guarded(s, fn, [&] {
    s->stepper.set_temperature(temperature_C);
    return GMASIM_OK;
  });
}

int gmasim_sim_time_s(const gmasim_sim* sim, double* out) {
  return get(sim, out, "gmasim_sim_time_s", [](const gmasim::Stepper& s) { return s.t_s(); });
}

int gmasim_sim_dt_s(const gmasim_sim* sim, double* out) {
  return get(sim, out, "gmasim_sim_dt_s", [](const gmasim::Stepper& s) { return s.dt_s(); });
}

int gmasim_sim_steps(const gmasim_sim* sim, long* out) {
  return get(sim, out, "gmasim_sim_steps", [](const gmasim::Stepper& s) { return s.steps(); });
}

int gmasim_sim_current_A(const gmasim_sim* sim, double* out) {
  return get(sim, out, "gmasim_sim_current_A",
             [](const gmasim::Stepper& s) { return s.state().current_A; });
}

int gmasim_sim_temperature_C(const gmasim_sim* sim, double* out) {
  return get(sim, out, "gmasim_sim_temperature_C",
             [](const gmasim::Stepper& s) { return s.temperature_C(); });
}

int gmasim_sim_y_m(const gmasim_sim* sim, double* out) {
  return get(sim, out, "gmasim_sim_y_m", [](const gmasim::Stepper& s) { return s.y_m(); });
}

int gmasim_sim_y_um(const gmasim_sim* sim, double* out) {
  return get(sim, out, "gmasim_sim_y_um", [](const gmasim::Stepper& s) { return s.y_m() * 1e6; });
}

int gmasim_sim_B_T(const gmasim_sim* sim, double* out) {
  return get(sim, out, "gmasim_sim_B_T", [](const gmasim::Stepper& s) { return s.B_T(); });
}

int gmasim_sim_diverged(const gmasim_sim* sim, int* out) {
  return get(sim, out, "gmasim_sim_diverged",
             [](const gmasim::Stepper& s) { return s.diverged() ? 1 : 0; });
}

int gmasim_sim_rod_count(const gmasim_sim* sim, int* out) {
  return get(sim, out, "gmasim_sim_rod_count",
             [](const gmasim::Stepper& s) { return s.rod_count(); });
}

int gmasim_sim_rod_force_N(const gmasim_sim* sim, int rod, double* out) {
  return get_rod(sim, rod, out, "gmasim_sim_rod_force_N",
                 [](const gmasim::RodState& r) { return r.F_N; });
}

int gmasim_sim_rod_strain(const gmasim_sim* sim, int rod, double* out) {
  return get_rod(sim, rod, out, "gmasim_sim_rod_strain",
                 [](const gmasim::RodState& r) { return r.lambda; });
}

int gmasim_sim_rod_magnetisation_A_per_m(const gmasim_sim* sim, int rod, double* out) {
  return get_rod(sim, rod, out, "gmasim_sim_rod_magnetisation_A_per_m",
                 [](const gmasim::RodState& r) { return r.M_A_per_m; });
}

int gmasim_sim_outputs(const gmasim_sim* sim, gmasim_outputs* out) {
  const char* fn = "gmasim_sim_outputs";
  const SimObject* so = object_of(sim);
  if (!so) return bad_handle(sim, fn, "sim", kDeadSim);
  if (!out) return null_argument(so, fn, "out");
  const gmasim::Stepper& st = so->stepper;
  const gmasim::State& s = st.state();
  *out = gmasim_outputs{};
  out->t_s = s.t_s;
  out->dt_s = st.dt_s();
  out->current_A = s.current_A;
  out->temperature_C = st.temperature_C();
  out->y_m = s.y_m;
  out->y_um = s.y_m * 1e6;
  out->y_stack_m = s.y_stack_m;
  out->B_T = s.B_T;
  out->thermal_expansion_m = st.conditions().thermal_expansion_m;
  out->steps = st.steps();
  out->rod_count = st.rod_count();
  out->diverged = st.diverged() ? 1 : 0;
  for (std::size_t i = 0; i < s.rods.size() && i < GMASIM_MAX_RODS; ++i) {
    const gmasim::RodState& r = s.rods[i];
    out->rod_F_N[i] = r.F_N;
    out->rod_strain[i] = r.lambda;
    out->rod_M_A_per_m[i] = r.M_A_per_m;
    out->rod_H_A_per_m[i] = r.H_A_per_m;
    out->rod_B_T[i] = r.B_T;
    out->rod_x_m[i] = r.x_m;
    out->rod_E_Pa[i] = r.E_Pa;
    out->rod_mu_r[i] = r.mu_r;
  }
  return GMASIM_OK;
}

}  // extern "C"
