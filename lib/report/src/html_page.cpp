#include "articula/report/html_page.hpp"

#include "articula/report/markup_text.hpp"

namespace articula::report {
namespace {

constexpr const char* kContentSecurityPolicy =
    "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'unsafe-inline'; "
    "style-src 'unsafe-inline'; img-src data:\">";

// Runs first: the page's problems go into <html data-page-problems> and a
// red list at the top of the page.
constexpr const char* kProblemRecorder = R"JS(<script>
(function () {
  var problems = [];
  function record(text) {
    problems.push(text);
    document.documentElement.setAttribute('data-page-problems', JSON.stringify(problems));
    var list = document.getElementById('page-problems');
    if (!list && document.body) {
      list = document.createElement('ul');
      list.id = 'page-problems';
      list.style.color = '#b00020';
      document.body.insertBefore(list, document.body.firstChild);
    }
    if (list) {
      var item = document.createElement('li');
      item.textContent = 'This page has a problem: ' + text;
      list.appendChild(item);
    }
  }
  window.addEventListener('error', function (e) { record('script error: ' + e.message); });
  document.addEventListener('securitypolicyviolation', function (e) {
    record('blocked request to ' + e.blockedURI + ' (' + e.violatedDirective + ')');
  });
})();
</script>)JS";

}  // namespace

std::string htmlPageStart(const std::string& title, const std::string& style) {
  return std::string("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n") + kContentSecurityPolicy +
         "\n" + kProblemRecorder + "\n<title>" + escapeMarkup(title) + "</title>\n<style>" + style +
         "</style></head>\n<body>\n";
}

}  // namespace articula::report
