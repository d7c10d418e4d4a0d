#pragma once
// The head of the project's offline pages (report.html, study.html): a
// content security policy under which nothing the page holds may fetch
// anything (scripts and styles inline, images data: addresses), and a
// recorder that lists on the page itself any script error or blocked
// request, so that a broken page says so to its reader (and to a check).
#include <string>

namespace articula::report {

/// "<!DOCTYPE html> ... <body>\n": the title escaped, the style inlined.
std::string htmlPageStart(const std::string& title, const std::string& style);

}  // namespace articula::report
