#include "articula/study/ratings.hpp"

#include <algorithm>

#include "articula/core/csv.hpp"
#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/core/log.hpp"

namespace articula::study {

std::map<std::string, Rating> readRatings(const std::filesystem::path& study_dir, const std::vector<pipeline::Subject>& subjects) {
  const std::filesystem::path path = study_dir / kRatingsFile;
  std::map<std::string, Rating> ratings;
  if (!std::filesystem::exists(path)) return ratings;
  const CsvTable table = readCsv(path);
  const int subject = table.column("subject"), decision = table.column("decision"), note = table.column("note");
  if (subject < 0 || decision < 0)
    throw InputError("'" + path.string() + "': expected the columns subject,decision[,note], found " +
                     excerpt(csvLine(table.header)));
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const auto& row = table.rows[r];
    const std::string where = "'" + path.string() + "' line " + std::to_string(table.row_lines[r]);
    const std::string id = row[static_cast<size_t>(subject)], choice = row[static_cast<size_t>(decision)];
    if (choice != "include" && choice != "exclude")
      throw InputError(where + ": expected the decision include or exclude, found '" + excerpt(choice) + "'");
    if (ratings.count(id)) throw InputError(where + ": subject '" + excerpt(id) + "' is rated twice");
    if (std::none_of(subjects.begin(), subjects.end(), [&id](const pipeline::Subject& s) { return s.id == id; })) {
      log::warn(where + ": subject '" + excerpt(id) + "' is not in the manifest; its rating is left aside");
      continue;
    }
    ratings[id] = {choice, note >= 0 ? row[static_cast<size_t>(note)] : ""};
  }
  return ratings;
}

}  // namespace articula::study
