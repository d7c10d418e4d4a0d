// The stage options' declarations (pipeline/stage_options.hpp): their
// defaults pass their own checks, options that stages share in run agree,
// the declared ranges are those the libraries refuse beyond, and the
// command-line adapter sets the fields and passes run's values on.
#include <set>

#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/pipeline/stage_options.hpp"
#include "articula/pipeline/stage_options_cli.hpp"
#include "articula/pipeline/stages.hpp"

namespace p = articula::pipeline;

namespace {

std::vector<std::string> valuesOf(const p::StageOption& option, const std::string& text) {
  const p::OptionType type = option.type();
  return type == p::OptionType::Numbers || type == p::OptionType::Choices ? p::splitList(text)
                                                                          : std::vector<std::string>{text};
}

// The library's own checks of a stage's options structs (the command-line
// only stages, errors and report, have none).
void validateInLibrary(const std::string& stage, p::StageSettings s) {
  if (stage == "segment") s.segment().head.validate();
  if (stage == "mesh") {
    s.mesh().surface.validate();
    s.mesh().edges.validate();
  }
  if (stage == "sample") {
    s.sample().selection.validate();
    s.sample().downsampling.validate();
  }
}

void setNumber(const p::StageOption& option, p::StageSettings& settings, double value) {
  std::visit(
      [value](auto* field) {
        using T = std::decay_t<decltype(*field)>;
        if constexpr (std::is_same_v<T, double>) *field = value;
        if constexpr (std::is_same_v<T, int>) *field = static_cast<int>(value);
      },
      option.field(settings));
}

// Parses `args` (after the program name) with `app`.
void parse(CLI::App& app, std::vector<std::string> args) {
  std::reverse(args.begin(), args.end());
  app.parse(args);
}

}  // namespace

TEST(StageOptions, EveryDefaultPassesItsOwnCheck) {
  int options = 0;
  for (const auto& stage : p::stages())
    for (const auto& option : stage.options) {
      ++options;
      const std::string text = option.defaultText();
      if (text.empty() || option.type() == p::OptionType::Flag) continue;
      EXPECT_EQ(option.problem(valuesOf(option, text)), "") << stage.name << " --" << option.name;
    }
  EXPECT_EQ(options, 46);
}

TEST(StageOptions, NamesAreUniqueAndSharedRunNamesAgree) {
  std::set<std::string> run_names;
  for (const auto& stage : p::stages()) {
    std::set<std::string> names;
    for (const auto& option : stage.options) {
      EXPECT_TRUE(names.insert(option.name).second) << stage.name << " declares --" << option.name << " twice";
      run_names.insert(option.runName());
    }
  }
  for (const std::string& name : run_names) {
    const auto takers = p::optionsRunAs(name);
    ASSERT_FALSE(takers.empty());
    for (const auto& taker : takers) {
      EXPECT_EQ(taker.option->type(), takers.front().option->type()) << name;
      EXPECT_EQ(taker.option->defaultValue(), takers.front().option->defaultValue()) << name;
      EXPECT_EQ(taker.option->unit, takers.front().option->unit) << name;
    }
  }
  // The same name, another meaning: errors' colour band is --errors-band in run.
  ASSERT_EQ(p::optionsRunAs("band").size(), 1u);
  EXPECT_EQ(p::optionsRunAs("band").front().stage, "sample");
  EXPECT_EQ(p::optionsRunAs("errors-band").front().option->name, "band");
  EXPECT_EQ(p::optionsRunAs("min-radius").size(), 2u);
  EXPECT_EQ(p::optionsRunAs("series-uid").size(), 3u);
}

TEST(StageOptions, ProblemsNameTheOptionAndItsRange) {
  const auto find = [](const std::string& stage, const std::string& name) {
    for (const auto& option : p::stageOptions(stage))
      if (option.name == name) return option;
    throw std::runtime_error("no --" + name);
  };
  EXPECT_EQ(find("segment", "hu-min").problem({"99999"}), "--hu-min (HU): expected -2000 to 10000, found 99999");
  EXPECT_EQ(find("segment", "hu-min").problem({"-2000"}), "");
  EXPECT_EQ(find("segment", "hu-min").problem({"12x"}), "--hu-min (HU): expected a number, found '12x'");
  EXPECT_NE(find("segment", "surface-hu").problem({"nan"}), "");
  EXPECT_EQ(find("segment", "level-set").problem({"2.5"}), "--level-set: expected a whole number, found '2.5'");
  EXPECT_EQ(find("segment", "seed-point").problem({"1", "2"}),
            "--seed-point (mm): expected 3 numbers separated by commas, found 2");
  EXPECT_EQ(find("sample", "ratio").problem({"0"}), "--ratio: expected above 0, up to 1, found 0");
  EXPECT_EQ(find("sample", "ratio").problem({"1"}), "");
  EXPECT_EQ(find("fit", "models").problem({"sphere", "cube"}),
            "--models: expected each of sphere, ellipsoid, superellipsoid, ovoid, superovoid, found 'cube'");
  EXPECT_EQ(find("mesh", "smoothing").problem({"sinc"}), "");
  EXPECT_NE(find("mesh", "smoothing").problem({"gauss"}), "");
  EXPECT_EQ(find("segment", "hu-min").json()["default"], 200.0);
  EXPECT_EQ(find("fit", "models").defaultText(), "sphere,ellipsoid,superellipsoid,ovoid,superovoid");
}

// Just beyond a declared range the library refuses too, so that the command
// line and the library's callers meet one rule; the only exceptions are the
// caps the command line adds where the library has none.
TEST(StageOptions, DeclaredRangesAreTheLibrariesOwn) {
  const std::set<std::string> command_line_caps = {"segment --label-value max", "segment --label-value min",
                                                   "sample --ball-radius max", "sample --min-points max"};
  int checked = 0;
  for (const std::string stage : {"segment", "mesh", "sample"})
    for (const auto& option : p::stageOptions(stage))
      for (const std::string side : {"min", "max"}) {
        const std::optional<double> end = side == "min" ? option.min : option.max;
        if (!end || command_line_caps.count(stage + " --" + option.name + " " + side)) continue;
        const double beyond = side == "max" ? *end + 1 : option.above_min ? *end : *end - 1;
        p::StageSettings settings;
        setNumber(option, settings, beyond);
        EXPECT_THROW(validateInLibrary(stage, settings), articula::UsageError)
            << stage << " --" << option.name << " " << beyond;
        ++checked;
      }
  EXPECT_GE(checked, 30);
}

TEST(StageOptions, StageCommandLineSetsTheFieldsAndRefusesOutOfRange) {
  p::StageSettings settings;
  CLI::App app;
  p::addStageOptions(app, "segment", settings);
  parse(app, {"--hu-min", "150", "--seed-point", "1,2,3", "--label-value", "4"});
  EXPECT_EQ(settings.segment().head.hu_min, 150.0);
  EXPECT_EQ(settings.segment().seed_point, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(settings.segment().label_value, 4);
  EXPECT_EQ(settings.segment().head.hu_max, 3000.0);  // not given: the library's default

  p::StageSettings other;
  CLI::App refusing;
  p::addStageOptions(refusing, "segment", other);
  try {
    parse(refusing, {"--max-radius", "1e6"});
    ADD_FAILURE() << "--max-radius 1e6 accepted";
  } catch (const CLI::ValidationError& e) {
    EXPECT_STREQ(e.what(), "--max-radius (mm): expected 1 to 60, found 1e6");
  }
}

TEST(StageOptions, RunTakesEveryOptionAndPassesOnWhatWasGiven) {
  p::StageSettings settings;
  CLI::App app;
  const auto options = p::addRunOptions(app, settings);
  size_t declared = 0;
  for (const auto& stage : p::stages()) declared += stage.options.size();
  EXPECT_EQ(options.size(), declared - 4);  // --series-uid thrice, --min-radius and --max-radius twice: one each
  parse(app, {"--min-radius", "12", "--errors-band", "0.3", "--all-components", "--models", "sphere,ovoid",
              "--select", "sphere:1,2,3,4"});
  EXPECT_EQ(p::forwardedArguments("segment", options), (std::vector<std::string>{"--min-radius", "12"}));
  EXPECT_EQ(p::forwardedArguments("mesh", options), (std::vector<std::string>{"--all-components"}));
  EXPECT_EQ(p::forwardedArguments("sample", options),
            (std::vector<std::string>{"--select", "sphere:1,2,3,4", "--min-radius", "12"}));
  EXPECT_EQ(p::forwardedArguments("fit", options), (std::vector<std::string>{"--models", "sphere,ovoid"}));
  EXPECT_EQ(p::forwardedArguments("errors", options), (std::vector<std::string>{"--band", "0.3"}));
  EXPECT_TRUE(p::forwardedArguments("report", options).empty());

  // A value one stage of a shared option refuses: named with that stage.
  p::StageSettings other;
  CLI::App refusing;
  p::addRunOptions(refusing, other);
  try {
    parse(refusing, {"--min-radius", "70"});
    ADD_FAILURE() << "--min-radius 70 accepted";
  } catch (const CLI::ValidationError& e) {
    EXPECT_STREQ(e.what(), "the segment stage: --min-radius (mm): expected 1 to 60, found 70");
  }
}

// The run order follows the files: a stage after those that write its
// inputs, whatever order they are listed in; a file two stages write, an
// input nobody writes and a cycle are refused.
TEST(StageTable, RunOrderFollowsTheFilesEachStageReadsAndWrites) {
  const auto row = [](std::string name, std::vector<std::string> in, std::vector<std::string> out) {
    p::StageDescription s;
    s.name = std::move(name);
    s.inputs = std::move(in);
    s.outputs = std::move(out);
    return s;
  };
  const auto names = [](const std::vector<p::StageDescription>& stages) {
    std::vector<std::string> n;
    for (const auto& s : stages) n.push_back(s.name);
    return n;
  };
  const auto a = row("a", {"CT"}, {"a.out"}), b = row("b", {"a.out"}, {"b.out"}), c = row("c", {"b.out", "a.out"}, {"c.out"});
  const auto side = row("side", {"a.out"}, {"side.out"});
  EXPECT_EQ(names(p::inRunOrder({c, b, a})), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(names(p::inRunOrder({a, side, b, c})), (std::vector<std::string>{"a", "side", "b", "c"}));
  EXPECT_EQ(names(p::inRunOrder({a, b, c, side})), (std::vector<std::string>{"a", "b", "c", "side"}));
  EXPECT_THROW(p::inRunOrder({a, b, row("again", {"CT"}, {"b.out"})}), articula::ProcessingError);
  EXPECT_THROW(p::inRunOrder({a, row("lost", {"nowhere.out"}, {"x"})}), articula::ProcessingError);
  EXPECT_THROW(p::inRunOrder({a, row("p", {"q.out"}, {"p.out"}), row("q", {"p.out"}, {"q.out"})}), articula::ProcessingError);
  EXPECT_THROW(p::inRunOrder({a, a}), articula::ProcessingError);
  // The pipeline's own stages, as listed.
  EXPECT_EQ(names(p::inRunOrder(p::pipelineStages())),
            (std::vector<std::string>{"segment", "mesh", "sample", "fit", "errors", "report"}));
}
