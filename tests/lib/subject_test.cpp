// The report stage's Slicer markups.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "articula/subject/markups.hpp"
#include "articula/testsupport/scratch_dir.hpp"

namespace fs = std::filesystem;
using articula::testsupport::scratchDir;

TEST(Markups, SlicerSchemaInLps) {
  const fs::path dir = scratchDir("markups");
  articula::subject::writeSlicerMarkups(dir / "head.mrk.json", "femoral head",
                        {{"head_center", Eigen::Vector3d(1.5, -2, 3)}},
                        {{"axis_a", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(25, 0, 0)}});
  std::ifstream in(dir / "head.mrk.json");
  const auto doc = nlohmann::json::parse(in);
  EXPECT_NE(doc.at("@schema").get<std::string>().find("markups-schema-v1.0.3"), std::string::npos);
  const auto& fiducial = doc.at("markups").at(0);
  EXPECT_EQ(fiducial.at("type"), "Fiducial");
  EXPECT_EQ(fiducial.at("coordinateSystem"), "LPS");
  EXPECT_EQ(fiducial.at("controlPoints").at(0).at("position"), nlohmann::json({1.5, -2.0, 3.0}));
  EXPECT_EQ(doc.at("markups").at(1).at("type"), "Line");
  EXPECT_EQ(doc.at("markups").at(1).at("controlPoints").size(), 2u);
}
