// Batch manifests and the CSV they are read with.
#include <filesystem>

#include <gtest/gtest.h>

#include "articula/core/csv.hpp"
#include "articula/core/error.hpp"
#include "articula/pipeline/manifest.hpp"
#include "articula/testsupport/scratch_dir.hpp"

namespace p = articula::pipeline;
namespace fs = std::filesystem;
using articula::testsupport::scratchDir;
using articula::testsupport::writeText;

TEST(Csv, QuotedFieldsRoundTrip) {
  const fs::path dir = scratchDir("csv");
  const std::vector<std::string> fields = {"plain", "with,comma", "with \"quotes\"", "", "multi\nline"};
  writeText(dir / "t.csv", "a,b,c,d,e\n" + articula::csvLine(fields) + "\n# comment\n\n1,2\n");
  const articula::CsvTable t = articula::readCsv(dir / "t.csv");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0], fields);
  EXPECT_EQ(t.rows[1][1], "2");
  EXPECT_EQ(t.rows[1][4], "");
  EXPECT_EQ(t.row_lines[1], 6);
  writeText(dir / "bad.csv", "a,b\n1,2,3\n");
  try {
    articula::readCsv(dir / "bad.csv");
    FAIL();
  } catch (const articula::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2"), std::string::npos) << e.what();
  }
}

TEST(Manifest, ResolvesPathsAndOptions) {
  const fs::path dir = scratchDir("manifest");
  fs::create_directories(dir / "data");
  writeText(dir / "data" / "s1.nii.gz", "x");
  writeText(dir / "m.csv", "subject,input,joint,side,seed_point\ns1,data/s1.nii.gz,hip,left,\"1,2,3\"\ns2," +
                           (dir / "missing").string() + ",shoulder,right,\n");
  const auto subjects = p::readManifest(dir / "m.csv");
  ASSERT_EQ(subjects.size(), 2u);
  EXPECT_EQ(subjects[0].input, dir / "data" / "s1.nii.gz");
  EXPECT_EQ(subjects[0].options, (std::vector<std::string>{"--seed-point", "1,2,3"}));
  EXPECT_TRUE(subjects[1].options.empty());
  EXPECT_TRUE(p::checkSubjectInput(subjects[0]).empty());
  ASSERT_EQ(p::checkSubjectInput(subjects[1]).size(), 1u);
  EXPECT_NE(p::checkSubjectInput(subjects[1])[0].find("does not exist"), std::string::npos);

  auto rejects = [&](const std::string& text, const std::string& fragment) {
    writeText(dir / "bad.csv", text);
    try {
      p::readManifest(dir / "bad.csv");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const articula::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  rejects("id,input,joint,side\na,b,hip,left\n", "subject,input,joint,side");
  rejects("subject,input,joint,side\na,x,knee,left\n", "bad.csv:2: joint");
  rejects("subject,input,joint,side\na,x,hip,up\n", "side");
  rejects("subject,input,joint,side\na,x,hip,left\na,y,hip,left\n", "bad.csv:3: subject id 'a' appears twice");
  rejects("subject,input,joint,side\n../a,x,hip,left\n", "expected a folder name");
  rejects("subject,input,joint,side\n..,x,hip,left\n", "not starting with '.'");
  rejects("subject,input,joint,side,until\na,x,hip,left,sample\n", "--until is set by the batch");
  rejects("subject,input,joint,side,output\na,x,hip,left,o\n", "--output is set by the batch");
  rejects("subject,input,joint,side,Seed Point\na,x,hip,left,1\n", "expected an option name");
  rejects("subject,input,joint,side,ratio,ratio\na,x,hip,left,1,2\n", "column 'ratio' appears twice");
  rejects("subject,input,joint,side,x\n\x1b[31m,x,hip,left,1\n", "\\x1b[31m");
  rejects("subject,input,joint,side\n", "at least one subject");
  // Stage options' values, checked by their declarations, line and stage named.
  rejects("subject,input,joint,side,selection_alpha\na,x,hip,left,0.01\nb,x,hip,left,5\n",
          "bad.csv:3: column 'selection_alpha': the report stage: --selection-alpha: expected 0 to 0.5, found 5");
  rejects("subject,input,joint,side,min_radius\na,x,hip,left,70\n", "the segment stage: --min-radius (mm)");
  rejects("subject,input,joint,side,seed_point\na,x,hip,left,\"1,2\"\n", "expected 3 numbers");
  rejects("subject,input,joint,side,all_components\na,x,hip,left,yes\n", "expected true or false, found 'yes'");
  writeText(dir / "flags.csv", "subject,input,joint,side,all_components,errors_band\na,x,hip,left,true,0.3\nb,x,hip,left,false,\n");
  const auto flagged = p::readManifest(dir / "flags.csv");
  EXPECT_EQ(flagged[0].options, (std::vector<std::string>{"--all-components", "--errors-band", "0.3"}));
  EXPECT_TRUE(flagged[1].options.empty());
}

TEST(Manifest, SpreadsheetByteOrderMarkIsNoPartOfTheHeader) {
  const fs::path dir = scratchDir("manifest_bom");
  writeText(dir / "m.csv", "\xEF\xBB\xBFsubject,input,joint,side\ns1,a.nii,hip,left\n");
  const auto subjects = p::readManifest(dir / "m.csv");
  ASSERT_EQ(subjects.size(), 1u);
  EXPECT_EQ(subjects[0].id, "s1");
  writeText(dir / "m.csv", "\xEF\xBB\xBFid,input,joint,side\ns1,a.nii,hip,left\n");
  try {
    p::readManifest(dir / "m.csv");
    ADD_FAILURE() << "accepted a header without subject";
  } catch (const articula::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("found 'id,input,joint,side'"), std::string::npos) << e.what();
  }
}
