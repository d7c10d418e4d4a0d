#include "articula/pipeline/manifest.hpp"

#include <set>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/core/csv.hpp"
#include "articula/imaging/io.hpp"
#include "articula/pipeline/stage_options.hpp"

namespace articula::pipeline {

namespace fs = std::filesystem;

namespace {
// Options the batch sets for every subject itself (where its outputs go, which
// stages run, how it is seeded and reported); a column may not override them.
const std::set<std::string> kBatchOwnedOptions = {"input", "output", "joint",  "side",  "seed",   "threads", "from",
                                                  "until", "force",  "json",   "quiet", "verbose", "config", "help",
                                                  "version", "i",    "o",      "q",     "v"};

// A column name becomes `--name` on the subject's command line.
void checkOptionColumn(const std::string& column, const fs::path& manifest) {
  const std::string where = manifest.string() + ":1: column '" + excerpt(column) + "': ";
  if (column.empty() || column.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_-") != std::string::npos ||
      column[0] == '-' || column[0] == '_')
    throw InputError(where + "expected an option name of lower-case letters, digits, '_' or '-' (e.g. seed_point)");
  std::string option = column;
  for (char& ch : option)
    if (ch == '_') ch = '-';
  if (kBatchOwnedOptions.count(option))
    throw InputError(where + "--" + option +
                     " is set by the batch for every subject (outputs go to STUDYDIR/<subject>, every stage runs); "
                     "a manifest column may set a stage option only");
}
// A cell of a column: `--name value`, a flag's `--name` when it is true.
// A stage option's value is checked by its declaration (stage_options.hpp)
// here, where its line is known; a column that names no stage option is
// left to run's parser, which the batch asks before any subject runs.
void addOption(std::vector<std::string>& options, const std::string& column, const std::string& value,
               const std::string& where) {
  std::string name = column;
  for (char& ch : name)
    if (ch == '_') ch = '-';
  const std::vector<StageOptionOf> declared = optionsRunAs(name);
  if (!declared.empty() && declared.front().option->type() == OptionType::Flag) {
    if (value != "true" && value != "false")
      throw InputError(where + "column '" + column + "': expected true or false, found '" + excerpt(value) + "'");
    if (value == "true") options.push_back("--" + name);
    return;
  }
  for (const StageOptionOf& taker : declared) {
    const OptionType type = taker.option->type();
    const bool list = type == OptionType::Numbers || type == OptionType::Choices;
    const std::string problem = taker.option->problem(list ? splitList(value) : std::vector<std::string>{value});
    if (!problem.empty()) throw InputError(where + "column '" + column + "': the " + taker.stage + " stage: " + problem);
  }
  options.insert(options.end(), {"--" + name, value});
}
}  // namespace

std::vector<Subject> readManifest(const fs::path& manifest) {
  const CsvTable table = readCsv(manifest);
  const char* required[] = {"subject", "input", "joint", "side"};
  for (size_t i = 0; i < 4; ++i)
    if (table.header.size() <= i || table.header[i] != required[i])
      throw InputError(manifest.string() + ":1: expected the header to start with subject,input,joint,side, found '" +
                       excerpt(csvLine(table.header), 120) + "'");
  std::set<std::string> columns;
  for (size_t c = 4; c < table.header.size(); ++c) {
    checkOptionColumn(table.header[c], manifest);
    if (!columns.insert(table.header[c]).second)
      throw InputError(manifest.string() + ":1: column '" + table.header[c] + "' appears twice");
  }
  const fs::path base = fs::absolute(manifest).parent_path();
  std::vector<Subject> subjects;
  std::set<std::string> seen;
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const auto& row = table.rows[r];
    const std::string where = manifest.string() + ":" + std::to_string(table.row_lines[r]) + ": ";
    Subject s;
    s.id = row[0];
    s.line = table.row_lines[r];
    if (s.id.empty()) throw InputError(where + "expected a subject id, found an empty field");
    if (s.id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") != std::string::npos ||
        s.id[0] == '.' || s.id.size() > 128)
      throw InputError(where + "subject id '" + excerpt(s.id) +
                       "': expected a folder name of letters, digits, '.', '_' or '-', not starting with '.' "
                       "(no '.', '..' or hidden folders), at most 128 characters");
    if (!seen.insert(s.id).second) throw InputError(where + "subject id '" + s.id + "' appears twice");
    if (row[1].empty()) throw InputError(where + "expected an input path for subject '" + s.id + "'");
    s.input = fs::path(row[1]).is_absolute() ? fs::path(row[1]) : (base / row[1]).lexically_normal();
    s.joint = row[2].empty() ? "hip" : row[2];
    s.side = row[3].empty() ? "right" : row[3];
    if (s.joint != "hip" && s.joint != "shoulder")
      throw InputError(where + "joint: expected hip or shoulder, found '" + excerpt(s.joint) + "'");
    if (s.side != "left" && s.side != "right")
      throw InputError(where + "side: expected left or right, found '" + excerpt(s.side) + "'");
    for (size_t c = 4; c < table.header.size(); ++c)
      if (!row[c].empty()) addOption(s.options, table.header[c], row[c], where);
    subjects.push_back(std::move(s));
  }
  if (subjects.empty()) throw InputError(manifest.string() + ": expected at least one subject row, found none");
  return subjects;
}

std::vector<std::string> checkSubjectInput(const Subject& s, bool scan_series) {
  std::vector<std::string> problems;
  std::error_code ec;
  if (!fs::exists(s.input, ec)) {
    problems.push_back("input '" + s.input.string() + "' does not exist");
  } else if (fs::is_directory(s.input, ec)) {
    bool any = false;
    for (const auto& entry : fs::directory_iterator(s.input, ec))
      if (entry.is_regular_file()) {
        any = true;
        break;
      }
    if (!any) {
      problems.push_back("input folder '" + s.input.string() + "' holds no files (expected a DICOM series)");
    } else if (scan_series) {
      try {
        imaging::listDicomSeries(s.input);
      } catch (const Error& e) {
        problems.push_back(e.what());
      }
    }
  } else {
    const std::string name = s.input.filename().string();
    auto ends = [&name](const std::string& suffix) {
      return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    if (!(ends(".nii") || ends(".nii.gz") || ends(".nrrd") || ends(".nhdr") || ends(".mha") || ends(".mhd")))
      problems.push_back("input '" + s.input.string() +
                         "': expected a DICOM folder or a .nii/.nii.gz/.nrrd/.mha image");
    else if (fs::file_size(s.input, ec) == 0)
      problems.push_back("input '" + s.input.string() + "' is empty");
  }
  return problems;
}

}  // namespace articula::pipeline
