// The stage runner (pipeline/runner.hpp) on a small phantom: what it runs
// and skips, by its own record of each stage.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "articula/core/error.hpp"
#include "articula/imaging/io.hpp"
#include "articula/phantom/phantom.hpp"
#include "articula/pipeline/runner.hpp"
#include "ct_test_support.hpp"

namespace articula {
namespace {

namespace fs = std::filesystem;
using pipeline::StageOutcome;
using Names = std::vector<std::string>;

const Names kAll = {"segment", "mesh", "sample", "fit", "errors", "report"};

// A small spherical-head phantom's CT (1.2 x 1.2 x 1.5 mm voxels: the whole
// chain in a few seconds) at `path`; `radius_mm` > 0 sets the head's radius.
void writePhantomCt(const fs::path& path, double radius_mm = 0) {
  phantom::PhantomOptions o;
  o.seed = 5;
  o.model = geometry::ShapeModel::Sphere;
  o.spacing = Eigen::Vector3d(1.2, 1.2, 1.5);
  if (radius_mm > 0) o.head_radius_mm = radius_mm;
  imaging::writeVolume(path, phantom::makePhantom(o).ct);
}

std::string fileText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class Runner : public ::testing::Test {
 protected:
  // A run of the phantom in a fresh folder `name`, quiet, on one thread, its
  // edges on the steepest fall and two models fitted (the blurred-cortex
  // model, the default on these voxels, would triple its time, the other
  // three fits double it; the runner depends on neither).
  pipeline::SubjectRun phantomRun(const std::string& name) {
    dir_ = testing::scratch("runner-" + name);
    pipeline::SubjectRun run;
    run.input = dir_ / "ct.nii.gz";
    run.output = dir_ / "subject";
    run.verbosity = 0;
    run.threads = 1;
    run.stage_options["mesh"] = {"--edge-model", "steepest"};
    run.stage_options["fit"] = {"--models", "sphere,ellipsoid"};
    writePhantomCt(run.input);
    return run;
  }
  void TearDown() override {
    if (!dir_.empty() && !HasFailure()) fs::remove_all(dir_);
  }

 private:
  fs::path dir_;
};

Names ran(const pipeline::RunRecord& r) { return r.stagesThat(StageOutcome::Ran); }
Names upToDate(const pipeline::RunRecord& r) { return r.stagesThat(StageOutcome::UpToDate); }

TEST_F(Runner, PlansEachStageWithItsFilesAndOnlyItsOptions) {
  pipeline::SubjectRun run;
  run.input = "/data/ct.nii.gz";
  run.output = "/out/s1";
  run.joint = "shoulder";
  run.side = "left";
  run.seed = 7;
  run.threads = 3;
  run.verbosity = 2;
  run.stage_options["fit"] = {"--models", "sphere,ellipsoid"};
  const std::vector<pipeline::StagePlan> plans = pipeline::planStages(run);
  ASSERT_EQ(plans.size(), kAll.size());
  for (size_t i = 0; i < plans.size(); ++i) EXPECT_EQ(plans[i].stage, kAll[i]);
  EXPECT_EQ(plans[0].arguments, (Names{"-i", "/data/ct.nii.gz", "-o", "/out/s1/label.nii.gz", "--joint", "shoulder",
                                       "--side", "left", "--seed", "7", "--threads", "3", "--force", "--verbose"}));
  EXPECT_EQ(plans[1].inputs, (std::vector<fs::path>{"/out/s1/label.nii.gz", "/data/ct.nii.gz"}));
  EXPECT_EQ(plans[3].arguments,
            (Names{"-i", "/out/s1/points.ply", "-o", "/out/s1/fits.json", "--grid", "/out/s1/label.nii.gz", "--models",
                   "sphere,ellipsoid", "--seed", "7", "--threads", "3", "--force", "--verbose"}));
  EXPECT_EQ(plans[3].inputs, (std::vector<fs::path>{"/out/s1/points.ply", "/out/s1/label.nii.gz"}));
  EXPECT_EQ(plans[3].outputs, (std::vector<fs::path>{"/out/s1/fits.json", "/out/s1/fits.csv"}));
  EXPECT_EQ(pipeline::argumentsProblem(run), "");

  run.from = "fit";
  run.until = "errors";
  const std::vector<pipeline::StagePlan> two = pipeline::planStages(run);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].stage, "fit");
  EXPECT_EQ(two[1].stage, "errors");

  // Refused before any work: a range backwards, a stage that is none, a
  // stage option its command refuses (named with its stage).
  run.from = "report";
  EXPECT_THROW(pipeline::planStages(run), UsageError);
  run.from = "nosuch";
  EXPECT_THROW(pipeline::planStages(run), UsageError);
  run.from.clear();
  run.until.clear();
  run.stage_options["fit"] = {"--max-evaluations", "0"};
  EXPECT_NE(pipeline::argumentsProblem(run).find("the fit stage: "), std::string::npos)
      << pipeline::argumentsProblem(run);
  EXPECT_THROW(pipeline::checkSubjectRun(run), UsageError);
}

TEST_F(Runner, ASecondRunSkipsEveryStage) {
  const pipeline::SubjectRun run = phantomRun("again");
  const pipeline::RunRecord first = pipeline::runSubject(run);
  ASSERT_EQ(first.exit_code, 0);
  EXPECT_EQ(ran(first), kAll);
  const std::string results = fileText(run.output / "results.json");
  EXPECT_NE(results.find("\"selected_model\""), std::string::npos);

  const pipeline::RunRecord second = pipeline::runSubject(run);
  EXPECT_EQ(second.exit_code, 0);
  EXPECT_EQ(upToDate(second), kAll);
  EXPECT_TRUE(ran(second).empty());
  EXPECT_EQ(fileText(run.output / "results.json"), results);
}

TEST_F(Runner, AChangedStageOptionRerunsThatStageAndTheLaterOnes) {
  pipeline::SubjectRun run = phantomRun("option");
  ASSERT_EQ(ran(pipeline::runSubject(run)), kAll);
  const std::string label = fileText(run.output / "label.nii.gz");
  // Fewer models: other fits, so errors and the report that read them rerun.
  run.stage_options["fit"] = {"--models", "sphere"};
  const pipeline::RunRecord changed = pipeline::runSubject(run);
  EXPECT_EQ(upToDate(changed), (Names{"segment", "mesh", "sample"}));
  EXPECT_EQ(ran(changed), (Names{"fit", "errors", "report"}));
  EXPECT_EQ(fileText(run.output / "label.nii.gz"), label);
  const nlohmann::json fits = nlohmann::json::parse(fileText(run.output / "fits.json"));
  ASSERT_EQ(fits.at("models").size(), 1u);
  EXPECT_EQ(fits.at("models")[0].at("model"), "sphere");
  // The same option again: nothing to do.
  EXPECT_EQ(upToDate(pipeline::runSubject(run)), kAll);
}

TEST_F(Runner, FromAndUntilBoundTheStagesRun) {
  pipeline::SubjectRun run = phantomRun("range");
  // From a stage whose inputs no earlier stage has written: refused, and no
  // trace left in the output folder.
  run.from = "fit";
  EXPECT_THROW(pipeline::runSubject(run), InputError);
  EXPECT_FALSE(fs::exists(run.output));

  run.from.clear();
  run.until = "sample";
  EXPECT_EQ(ran(pipeline::runSubject(run)), (Names{"segment", "mesh", "sample"}));
  EXPECT_TRUE(fs::exists(run.output / "points.ply"));
  EXPECT_FALSE(fs::exists(run.output / "fits.json"));

  run.from = "fit";
  run.until.clear();
  EXPECT_EQ(ran(pipeline::runSubject(run)), (Names{"fit", "errors", "report"}));

  // The stage --from names is rerun though up to date; the rest of the
  // range only if its inputs changed.
  run.from = "sample";
  run.until = "fit";
  const pipeline::RunRecord again = pipeline::runSubject(run);
  EXPECT_EQ(ran(again), (Names{"sample"}));
  EXPECT_EQ(upToDate(again), (Names{"fit"}));
}

TEST_F(Runner, AMissingOrDamagedOutputRerunsItsStage) {
  pipeline::SubjectRun run = phantomRun("outputs");
  ASSERT_EQ(ran(pipeline::runSubject(run)), kAll);
  // A missing output: its stage reruns and writes the same points, so the
  // stages after it are up to date.
  const std::string points = fileText(run.output / "points.ply");
  fs::remove(run.output / "points.ply");
  const pipeline::RunRecord missing = pipeline::runSubject(run);
  EXPECT_EQ(ran(missing), (Names{"sample"}));
  EXPECT_EQ(upToDate(missing), (Names{"segment", "mesh", "fit", "errors", "report"}));
  EXPECT_EQ(fileText(run.output / "points.ply"), points);
  // A damaged output: its stage reruns, and the stages that read its
  // outputs, since fits.json records the fit's time.
  std::ofstream(run.output / "fits.csv", std::ios::app) << "1,2,3\n";
  const pipeline::RunRecord damaged = pipeline::runSubject(run);
  EXPECT_EQ(upToDate(damaged), (Names{"segment", "mesh", "sample"}));
  EXPECT_EQ(ran(damaged), (Names{"fit", "errors", "report"}));
}

TEST_F(Runner, AnotherCtOrForceRerunsTheStages) {
  pipeline::SubjectRun run = phantomRun("ct");
  run.until = "mesh";  // the stages that read the CT
  const Names both = {"segment", "mesh"};
  ASSERT_EQ(ran(pipeline::runSubject(run)), both);
  ASSERT_EQ(upToDate(pipeline::runSubject(run)), both);
  const std::string label = fileText(run.output / "label.nii.gz");
  // Another CT (a larger head) at the same path.
  writePhantomCt(run.input, 26.0);
  EXPECT_EQ(ran(pipeline::runSubject(run)), both);
  EXPECT_NE(fileText(run.output / "label.nii.gz"), label);
  pipeline::SubjectRun forced = run;
  forced.force = true;
  EXPECT_EQ(ran(pipeline::runSubject(forced)), both);
}

}  // namespace
}  // namespace articula
