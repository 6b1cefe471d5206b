// --set of an option the model file omits, and a change of magnetisation law (issue 21):
// `gmasim model save --set options.magnetisation_law=preisach` adds the option to [options],
// comments out the old law's tables and writes the new law's from the --set numbers, which are
// then all required (an error names the missing ones).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/model.hpp"

using ::testing::HasSubstr;
using ::testing::Not;
using namespace gmasim;

namespace {

std::string model_path(const std::string& name) {
  return std::string(GMASIM_SOURCE_DIR) + "/models/" + name;
}

// The assignments that turn models/single_rod.toml into models/single_rod_preisach.toml.
std::vector<std::string> to_preisach_template() {
  return {"options.magnetisation_law=preisach",
          "rod.preisach.Hc0_A_per_m=3000",
          "rod.preisach.sigma_c=0.5",
          "rod.preisach.Hu0_A_per_m=6000",
          "rod.preisach.n_c=2",
          "rod.preisach.c0=0.1",
          "rod.preisach.a0_A_per_m=5947",
          "rod.preisach.alpha0=-0.0377"};
}

}  // namespace

// The single-rod template (no magnetisation_law line) saved as a Preisach model equals the
// shipped Preisach template: the same numbers and options, and the same compiled rod (its
// static state at 2 A, to the bit).
TEST(ModelSaveLaw, ChangingTheLawWritesTheNewLawsTable) {
  const ModelSpec ja = load_model_spec(model_path("single_rod.toml"));
  ASSERT_EQ(ja.option_lines.count("options.magnetisation_law"), 0u);
  const ModelSpec changed = apply_assignments(ja, to_preisach_template());
  const std::string text = model_toml(changed, "test");
  EXPECT_THAT(text, HasSubstr("magnetisation_law = \"preisach\"  # set: test"));
  EXPECT_THAT(text, HasSubstr("# [rod.ja]"));
  EXPECT_THAT(text, HasSubstr("# k0_A_per_m = 3032.0"));
  const ModelSpec back = parse_model_spec(text, "saved");
  const ModelSpec shipped = load_model_spec(model_path("single_rod_preisach.toml"));
  EXPECT_EQ(back.options, shipped.options);
  ASSERT_EQ(back.params.size(), shipped.params.size());
  for (const auto& [name, pv] : shipped.params) {
    ASSERT_EQ(back.params.count(name), 1u) << name;
    EXPECT_EQ(back.params.at(name).value, pv.value) << name;
  }
  const Model a = compile(back), b = compile(shipped);
  const Conditions ca = make_conditions(a, 20.0), cb = make_conditions(b, 20.0);
  const State sa = make_state(a, ca, 2.0), sb = make_state(b, cb, 2.0);
  EXPECT_EQ(sa.y_m, sb.y_m);
  EXPECT_EQ(sa.rods[0].M_A_per_m, sb.rods[0].M_A_per_m);
  EXPECT_NE(sa.rods[0].M_A_per_m, 0.0);
  // And back to Jiles-Atherton from the saved file: the JA numbers are required again.
  const ModelSpec again = apply_assignments(back, {"options.magnetisation_law=jiles_atherton"});
  try {
    (void)model_toml(again, "test");
    ADD_FAILURE() << "a law without its numbers was saved";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("rod.ja.k0_A_per_m"));
  }
}

// The law's numbers are required: the error names each missing one and how to give it, in
// model save and in any command that compiles the spec.
TEST(ModelSaveLaw, MissingNumbersOfTheNewLawAreNamed) {
  const ModelSpec ja = load_model_spec(model_path("single_rod.toml"));
  const ModelSpec changed =
      apply_assignments(ja, {"options.magnetisation_law=preisach", "rod.preisach.sigma_c=0.5"});
  for (int k = 0; k < 2; ++k) {
    try {
      if (k == 0) (void)model_toml(changed, "test");
      if (k == 1) (void)compile(changed);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_THAT(what, HasSubstr("options.magnetisation_law = \"preisach\""));
      EXPECT_THAT(what, HasSubstr("rod.preisach.Hc0_A_per_m"));
      EXPECT_THAT(what, HasSubstr("rod.preisach.alpha0"));
      EXPECT_THAT(what, Not(HasSubstr("rod.preisach.sigma_c")));
      EXPECT_THAT(what, HasSubstr("--set"));
    }
  }
  // A number of the new law is checked by its row like any other.
  try {
    (void)apply_assignments(ja, {"options.magnetisation_law=preisach", "rod.preisach.c0=1.5"});
    ADD_FAILURE() << "c0 = 1.5 accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("[0, 1)"));
  }
}

// An omitted option set to its default changes nothing: the file is saved as it was.
TEST(ModelSaveLaw, AnOmittedOptionAtItsDefaultLeavesTheFile) {
  const ModelSpec ja = load_model_spec(model_path("single_rod.toml"));
  const ModelSpec same = apply_assignments(ja, {"options.magnetisation_law=jiles_atherton"});
  EXPECT_EQ(model_toml(same, "test"), ja.text);
}

// Issue 39 item 2: the shipped Preisach template is the single-rod template with another law --
// the same numbers (geometry, material, preload, spring, circuit, thermal network) and options,
// but for options.magnetisation_law and the law's table ([meta] is text, not a parameter).
TEST(ModelSaveLaw, ThePreisachTemplateIsTheSingleRodWithAnotherLaw) {
  const ModelSpec ja = load_model_spec(model_path("single_rod.toml"));
  const ModelSpec pr = load_model_spec(model_path("single_rod_preisach.toml"));
  auto law_key = [](const std::string& name) {
    return name.starts_with("rod.ja.") || name.starts_with("rod.preisach.");
  };
  std::size_t shared = 0;
  for (const auto& [name, pv] : ja.params) {
    if (law_key(name)) continue;
    ASSERT_EQ(pr.params.count(name), 1u) << name << " is not in the Preisach template";
    EXPECT_EQ(pr.params.at(name).value, pv.value) << name;
    ++shared;
  }
  for (const auto& [name, pv] : pr.params) {
    if (!law_key(name)) {
      EXPECT_EQ(ja.params.count(name), 1u) << name << " is only in Preisach's";
    }
  }
  EXPECT_GT(shared, 30u);
  ModelSpec same_law = pr;
  same_law.set_option("options.magnetisation_law", "jiles_atherton");
  EXPECT_EQ(same_law.options, ja.options);
  EXPECT_NE(pr.options, ja.options);
}
