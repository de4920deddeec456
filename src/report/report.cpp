#include "demcal/report/report.hpp"

#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <sstream>
#include <thread>

#include "demcal/search/parallel.hpp"

namespace demcal {

namespace fs = std::filesystem;

void attach_runs(ReportInput& input, ResultRuns runs) {
  input.start = std::move(runs.start);
  input.best = std::move(runs.best);
  input.picture = std::move(runs.picture);
}

// ---------------------------------------------------------------------------
// gnuplot

std::string find_program(const std::string& name) {
  if (name.empty()) return "";
  auto executable = [](const std::string& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
  };
  if (name.find('/') != std::string::npos) return executable(name) ? name : "";
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/local/bin:/usr/bin:/bin";
  std::stringstream s(dirs);
  std::string dir;
  while (std::getline(s, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = dir + "/" + name;
    if (executable(candidate)) return candidate;
  }
  return "";
}

std::map<std::string, std::string> run_gnuplot(const std::string& program,
                                               const std::string& script,
                                               const std::map<std::string, std::string>& files,
                                               const std::vector<std::string>& outputs,
                                               std::string* error) {
  std::map<std::string, std::string> out;
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return out;
  };
  const std::string exe = find_program(program);
  if (exe.empty()) return fail(program + " not found");
  std::string tmpl = (fs::temp_directory_path() / "demcal-report-XXXXXX").string();
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  if (!::mkdtemp(buf.data())) return fail("cannot create a temporary folder");
  const fs::path dir(buf.data());
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{dir};
  auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream f(dir / name, std::ios::binary);
    f << content;
    return static_cast<bool>(f);
  };
  for (const auto& [name, content] : files) {
    if (name.find('/') != std::string::npos || !write(name, content))
      return fail("cannot write " + name);
  }
  if (!write("plots.gp", script)) return fail("cannot write the gnuplot script");

  // Everything the child needs is prepared before fork(): it only calls
  // async-signal-safe functions.
  const std::string dir_s = dir.string(), log_s = (dir / "gnuplot.log").string();
  std::vector<std::string> env_s{"HOME=" + dir_s, "LC_ALL=C.UTF-8", "LANG=C.UTF-8"};
  if (const char* path = std::getenv("PATH")) env_s.push_back(std::string("PATH=") + path);
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::string arg0 = "gnuplot", arg1 = "plots.gp";
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  const pid_t pid = ::fork();
  if (pid < 0) return fail("cannot start gnuplot (fork failed)");
  if (pid == 0) {
    if (::chdir(dir_s.c_str()) != 0) _exit(126);
    const int null_fd = ::open("/dev/null", O_RDONLY);
    const int log_fd = ::open(log_s.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (null_fd >= 0) ::dup2(null_fd, 0);
    if (log_fd >= 0) {
      ::dup2(log_fd, 1);
      ::dup2(log_fd, 2);
    }
    ::execve(exe.c_str(), argv, envp.data());
    _exit(127);
  }
  int status = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0) return fail("lost track of gnuplot");
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(30)) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return fail("gnuplot did not finish in 30 s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  for (const auto& name : outputs) {
    std::ifstream f(dir / name, std::ios::binary);
    if (!f) continue;
    std::ostringstream s;
    s << f.rdbuf();
    if (s.str().find("</svg>") == std::string::npos) continue;  // cut short by an error
    out[name] = s.str();
  }
  if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0) && error) {
    std::ifstream f(log_s);
    std::ostringstream s;
    s << f.rdbuf();
    std::string log;
    for (char c : s.str()) {
      const bool space = c == '\n' || c == '\r' || c == '\t' || c == ' ';
      if (space && (log.empty() || log.back() == ' ')) continue;
      log += space ? ' ' : c;
    }
    if (log.size() > 600) log = log.substr(0, 600) + "...";
    *error = "gnuplot failed: " + log;
  }
  return out;
}

namespace {

// ---------------------------------------------------------------------------
// Formatting

std::string num(double v, int sig = 4) {
  if (!std::isfinite(v)) return "n/a";
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", sig, v);
  return b;
}

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "n/a";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

std::string pct(double fraction, int decimals = 2) {
  if (!std::isfinite(fraction)) return "n/a";
  return fixed(100.0 * fraction, decimals) + " %";
}

std::string signed_pct(double fraction, int decimals = 2) {
  if (!std::isfinite(fraction)) return "n/a";
  return (fraction >= 0 ? "+" : "") + fixed(100.0 * fraction, decimals) + " %";
}

/// 1.23e6 style.
std::string sci(double v) {
  if (!std::isfinite(v)) return "n/a";
  if (v == 0.0) return "0";
  const int e = static_cast<int>(std::floor(std::log10(std::abs(v))));
  if (e >= -2 && e <= 4) return num(v, 4);
  char b[64];
  std::snprintf(b, sizeof b, "%.3ge%d", v / std::pow(10.0, e), e);
  return b;
}

std::string grouped(int64_t v) {
  std::string s = std::to_string(v < 0 ? -v : v), out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (i > 0 && (s.size() - i) % 3 == 0) out += ',';
    out += s[i];
  }
  return (v < 0 ? "-" : "") + out;
}

std::string kpa(double pa) { return num(pa / 1e3, 4) + " kPa"; }

std::string esc(const std::string& s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      case '\'':
        o += "&#39;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

std::string md_cell(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '|')
      o += "\\|";
    else if (c == '\n')
      o += ' ';
    else
      o += c;
  }
  return o;
}

/// A diagnosis message as a sentence: capital first letter, final period.
std::string sentence(std::string s) {
  while (!s.empty() && s.back() == ' ') s.pop_back();
  if (s.empty()) return s;
  if (s[0] >= 'a' && s[0] <= 'z') s[0] = static_cast<char>(s[0] - 'a' + 'A');
  if (s.back() != '.') s += '.';
  return s;
}

std::string params_text(const AlgorithmSpec& p) {
  return "α " + num(p.dt_ratio, 4) + ", Nstep " + grouped(p.steps) + ", ζ_t " +
         num(p.damping_ratio_translation, 4) + ", ζ_r " + num(p.damping_ratio_rotation, 4);
}

/// For gnuplot's enhanced text: plain digits and my own words only.
std::string params_gp(const AlgorithmSpec& p) {
  return "α = " + num(p.dt_ratio, 3) + ",  N_{step} = " + std::to_string(p.steps) +
         ",  ζ_t = " + num(p.damping_ratio_translation, 3) +
         ",  ζ_r = " + num(p.damping_ratio_rotation, 3);
}

// ---------------------------------------------------------------------------
// Writing HTML and Markdown side by side, so both carry the same facts.

class Doc {
 public:
  std::ostringstream html, md;

  void heading(int level, const std::string& text, const std::string& id = "") {
    html << "<h" << level << (id.empty() ? "" : " id=\"" + id + "\"") << ">" << esc(text) << "</h"
         << level << ">\n";
    md << std::string(level, '#') << ' ' << text << "\n\n";
  }
  void para(const std::string& text, const std::string& cls = "") {
    html << "<p" << (cls.empty() ? "" : " class=\"" + cls + "\"") << ">" << esc(text) << "</p>\n";
    md << text << "\n\n";
  }
  void bullets(const std::vector<std::string>& items) {
    html << "<ul>\n";
    for (const auto& i : items) html << "<li>" << esc(i) << "</li>\n";
    html << "</ul>\n";
    for (const auto& i : items) md << "- " << i << "\n";
    md << "\n";
  }
  void code(const std::string& text) {
    html << "<pre><code>" << esc(text) << "</code></pre>\n";
    md << "```sh\n" << text << "\n```\n\n";
  }
  void table(const std::vector<std::string>& head,
             const std::vector<std::vector<std::string>>& rows, const std::string& cls = "") {
    html << "<table" << (cls.empty() ? "" : " class=\"" + cls + "\"") << ">\n<thead><tr>";
    for (const auto& h : head) html << "<th>" << esc(h) << "</th>";
    html << "</tr></thead>\n<tbody>\n";
    for (const auto& r : rows) {
      html << "<tr>";
      for (const auto& c : r) {
        std::string klass;
        if (c == "pass" || c == "yes")
          klass = "ok";
        else if (c == "FAIL" || c == "diverged" || c == "no")
          klass = "bad";
        else if (c == "stopped early")
          klass = "warn";
        html << "<td" << (klass.empty() ? "" : " class=\"" + klass + "\"") << ">" << esc(c)
             << "</td>";
      }
      html << "</tr>\n";
    }
    html << "</tbody>\n</table>\n";
    md << '|';
    for (const auto& h : head) md << ' ' << md_cell(h) << " |";
    md << "\n|";
    for (size_t k = 0; k < head.size(); ++k) md << " --- |";
    md << '\n';
    for (const auto& r : rows) {
      md << '|';
      for (const auto& c : r) md << ' ' << md_cell(c) << " |";
      md << '\n';
    }
    md << '\n';
  }
  /// A figure: inline SVG in the HTML (or a note when it is missing); in
  /// the Markdown a pointer to report.html (the numbers are in the tables).
  void figure(const std::string& svg, const std::string& caption, const std::string& missing) {
    html << "<figure>\n";
    if (!svg.empty())
      html << svg << "\n";
    else
      html << "<div class=\"noplot\">" << esc(missing) << "</div>\n";
    html << "<figcaption>" << esc(caption) << "</figcaption>\n</figure>\n";
    md << "*Figure (in report.html): " << caption << "*\n\n";
  }
  void raw_html(const std::string& s) { html << s; }
  void details_begin(const std::string& summary) {
    html << "<details>\n<summary>" << esc(summary) << "</summary>\n<div class=\"scroll\">\n";
  }
  void details_end() { html << "</div>\n</details>\n"; }
};

// ---------------------------------------------------------------------------
// Facts shared by the sections

struct Ratios {
  double force_balance, moment_balance, servo, oscillation;
  double worst() const { return std::max({force_balance, moment_balance, servo, oscillation}); }
  std::string worst_name() const {
    const double w = worst();
    if (w == force_balance) return "force balance";
    if (w == moment_balance) return "moment balance";
    if (w == servo) return "servo";
    return "oscillation";
  }
};
Ratios ratios(const Criteria& c, const Tolerances& t) {
  return {c.force_balance / t.force_balance, c.moment_balance / t.moment_balance, c.servo / t.servo,
          c.oscillation / t.oscillation};
}

std::string verdict(const TrialRecord& t) {
  if (t.diverged) return "diverged";
  if (!t.complete) return "stopped early";
  return t.passed ? "pass" : "FAIL";
}

/// One trial in the history and the speed-vs-accuracy chart.
struct Point {
  std::string label;  ///< "12", "b3", "r8"
  std::string phase;
  const TrialRecord* trial = nullptr;
  double cost = 0.0;     ///< particle-steps planned
  double seconds = 0.0;  ///< wall time (extrapolated to the full run when stopped early)
  std::optional<double> peak_error;
  bool best = false;
};

double objective_of(const TrialRecord& t, const Tolerances& tol) {
  Score s;
  s.criteria = t.criteria;
  s.diverged = t.diverged;
  s.complete = t.complete;
  s.passed = t.passed;
  s.completed_fraction =
      t.params.steps > 0 ? static_cast<double>(t.steps_run) / static_cast<double>(t.params.steps)
                         : 0.0;
  s.particle_steps = t.particle_steps;
  return objective(s, tol);
}

// Data files for gnuplot: numbers only, '?' for a missing value.
std::string dat(double v) {
  if (!std::isfinite(v)) return "?";
  char b[48];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

struct Figure {
  std::string name;  ///< output file "name.svg"
  std::string script;
  std::string caption;
};

struct Plotter {
  std::map<std::string, std::string> files;
  std::vector<Figure> figures;

  static std::string terminal(int w, int h) {
    return "set terminal svg size " + std::to_string(w) + "," + std::to_string(h) +
           " dynamic enhanced font 'sans,11' background '#ffffff'\n";
  }
  static std::string common() {
    return "set encoding utf8\nset grid lc rgb '#e0e0e0' lw 1\nset border lc rgb '#555555'\n"
           "set key box lt rgb '#cccccc' opaque samplen 2.5 spacing 1.1 font ',10'\n"
           "set datafile missing '?'\n";
  }
};

/// Columns of a series file: 1 −ε_yy [%], 2 −b_yy, 3 −σ_yy, 4 σ_xy, 5 σ_yx,
/// 6 −b_xx, 7 −σ_xx [kPa], 8 servo error [%].
std::string series_dat(const std::vector<MonitorPoint>& s) {
  std::ostringstream o;
  for (const auto& p : s) {
    o << dat(-100.0 * p.strain_yy) << ' ' << dat(-p.b(1, 1) / 1e3) << ' '
      << dat(-p.sigma(1, 1) / 1e3) << ' ' << dat(p.sigma(0, 1) / 1e3) << ' '
      << dat(p.sigma(1, 0) / 1e3) << ' ' << dat(-p.b(0, 0) / 1e3) << ' '
      << dat(-p.sigma(0, 0) / 1e3) << ' ' << dat(100.0 * p.lateral_stress_error) << '\n';
  }
  return o.str();
}

double column(const MonitorPoint& p, int c) {
  switch (c) {
    case 2:
      return -p.b(1, 1) / 1e3;
    case 3:
      return -p.sigma(1, 1) / 1e3;
    case 4:
      return p.sigma(0, 1) / 1e3;
    case 5:
      return p.sigma(1, 0) / 1e3;
    case 6:
      return -p.b(0, 0) / 1e3;
    case 7:
      return -p.sigma(0, 0) / 1e3;
    case 8:
      return 100.0 * p.lateral_stress_error;
  }
  return 0.0;
}

std::string gp_range(double lo, double hi) {
  if (!(std::isfinite(lo) && std::isfinite(hi))) return "[*:*]";
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
    lo -= 1.0;
    hi += 1.0;
  }
  const double pad = 0.06 * (hi - lo);
  return "[" + dat(lo - pad) + ":" + dat(hi + pad) + "]";
}

// ---------------------------------------------------------------------------
// The assembly picture, drawn directly (no gnuplot needed).

std::string rotation_colour(double t) {  // t in [−1, 1]: blue, white, red
  t = std::clamp(t, -1.0, 1.0);
  const double white[3] = {247, 247, 247}, red[3] = {178, 24, 43}, blue[3] = {33, 102, 172};
  const double* end = t >= 0 ? red : blue;
  const double a = std::abs(t);
  char b[16];
  std::snprintf(b, sizeof b, "#%02x%02x%02x",
                static_cast<int>(std::lround(white[0] + a * (end[0] - white[0]))),
                static_cast<int>(std::lround(white[1] + a * (end[1] - white[1]))),
                static_cast<int>(std::lround(white[2] + a * (end[2] - white[2]))));
  return b;
}

std::string assembly_svg(const AssemblyPicture& p) {
  const double W = p.right - p.left, H = p.top - p.bottom;
  if (!(W > 0 && H > 0)) return "";
  const double pad = 14, img_w = 560, scale = img_w / W, img_h = H * scale;
  const double legend_x = pad + img_w + 36;
  const double total_w = legend_x + 150, total_h = std::max(img_h + 2 * pad, 300.0);
  auto X = [&](double x) { return fixed(pad + (x - p.left) * scale, 2); };
  auto Y = [&](double y) { return fixed(pad + (p.top - y) * scale, 2); };
  double tmax = 0.0, fmax = 0.0, rmean = 0.0;
  for (double t : p.rotation) tmax = std::max(tmax, std::abs(t));
  for (const auto& f : p.forces) fmax = std::max(fmax, f.fn);
  for (double r : p.r) rmean += r;
  rmean = p.r.empty() ? 0.0 : rmean / static_cast<double>(p.r.size());
  const double wmax = std::max(1.0, 0.45 * rmean * scale);  // line width at the largest force
  std::ostringstream s;
  s << "<svg class=\"assembly\" viewBox=\"0 0 " << fixed(total_w, 0) << ' ' << fixed(total_h, 0)
    << "\" role=\"img\" aria-label=\"assembly at the peak\">\n";
  s << "<defs><linearGradient id=\"asm-rot\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">"
    << "<stop offset=\"0\" stop-color=\"" << rotation_colour(-1) << "\"/>"
    << "<stop offset=\"0.5\" stop-color=\"" << rotation_colour(0) << "\"/>"
    << "<stop offset=\"1\" stop-color=\"" << rotation_colour(1) << "\"/>"
    << "</linearGradient></defs>\n";
  s << "<rect x=\"0\" y=\"0\" width=\"" << fixed(total_w, 0) << "\" height=\"" << fixed(total_h, 0)
    << "\" fill=\"#ffffff\"/>\n";
  s << "<g stroke=\"#777777\" stroke-width=\"0.6\">\n";
  for (size_t i = 0; i < p.x.size(); ++i)
    s << "<circle cx=\"" << X(p.x[i]) << "\" cy=\"" << Y(p.y[i]) << "\" r=\""
      << fixed(p.r[i] * scale, 2) << "\" fill=\""
      << rotation_colour(tmax > 0 ? p.rotation[i] / tmax : 0.0) << "\"/>\n";
  s << "</g>\n<g stroke-linecap=\"round\">\n";
  for (const auto& f : p.forces) {
    if (fmax <= 0) break;
    const double w = wmax * f.fn / fmax;
    if (w < 0.15) continue;
    s << "<line x1=\"" << X(f.x1) << "\" y1=\"" << Y(f.y1) << "\" x2=\"" << X(f.x2) << "\" y2=\""
      << Y(f.y2) << "\" stroke=\"" << (f.wall ? "#6b4f1d\" stroke-linecap=\"butt" : "#111111")
      << "\" stroke-width=\"" << fixed(w, 2) << "\"/>\n";
  }
  s << "</g>\n";
  // Walls.
  s << "<rect x=\"" << X(p.left) << "\" y=\"" << Y(p.top) << "\" width=\"" << fixed(img_w, 2)
    << "\" height=\"" << fixed(img_h, 2)
    << "\" fill=\"none\" stroke=\"#333333\" stroke-width=\"2.5\"/>\n";
  // Legend: rotation colour bar and force scale.
  const double bar_y = pad + 22, bar_h = 150;
  const double deg = tmax * 180.0 / std::numbers::pi;
  s << "<g font-family=\"sans-serif\" font-size=\"12\" fill=\"#222222\">\n";
  s << "<text x=\"" << fixed(legend_x - 10, 1) << "\" y=\"" << fixed(pad + 8, 1)
    << "\">rotation [°]</text>\n";
  s << "<rect x=\"" << fixed(legend_x, 1) << "\" y=\"" << fixed(bar_y, 1)
    << "\" width=\"18\" height=\"" << fixed(bar_h, 1)
    << "\" fill=\"url(#asm-rot)\" stroke=\"#555555\" stroke-width=\"0.6\"/>\n";
  s << "<text x=\"" << fixed(legend_x + 24, 1) << "\" y=\"" << fixed(bar_y + 5, 1) << "\">+"
    << num(deg, 3) << " (ccw)</text>\n";
  s << "<text x=\"" << fixed(legend_x + 24, 1) << "\" y=\"" << fixed(bar_y + bar_h / 2 + 4, 1)
    << "\">0</text>\n";
  s << "<text x=\"" << fixed(legend_x + 24, 1) << "\" y=\"" << fixed(bar_y + bar_h + 4, 1) << "\">−"
    << num(deg, 3) << " (cw)</text>\n";
  const double fy = bar_y + bar_h + 40;
  s << "<text x=\"" << fixed(legend_x - 10, 1) << "\" y=\"" << fixed(fy, 1)
    << "\">normal force</text>\n";
  for (int k = 0; k < 2; ++k) {
    const double frac = k == 0 ? 1.0 : 0.5;
    const double ly = fy + 22 + 24 * k;
    s << "<line x1=\"" << fixed(legend_x, 1) << "\" y1=\"" << fixed(ly, 1) << "\" x2=\""
      << fixed(legend_x + 30, 1) << "\" y2=\"" << fixed(ly, 1)
      << "\" stroke=\"#111111\" stroke-linecap=\"round\" stroke-width=\"" << fixed(wmax * frac, 2)
      << "\"/>\n";
    s << "<text x=\"" << fixed(legend_x + 40, 1) << "\" y=\"" << fixed(ly + 4, 1) << "\">"
      << num(fmax * frac, 3) << " N</text>\n";
  }
  s << "</g>\n</svg>";
  return s.str();
}

/// gnuplot's SVG made fit to sit inline in HTML: no XML prolog, no
/// namespace declarations (the HTML parser supplies them), ids made unique
/// per figure.
std::string inline_svg(std::string svg, const std::string& prefix, const std::string& label,
                       const std::string& css_class) {
  const size_t start = svg.find("<svg");
  if (start == std::string::npos) return "";
  svg = svg.substr(start);
  auto erase_all = [&](const std::string& what) {
    for (size_t k; (k = svg.find(what)) != std::string::npos;) svg.erase(k, what.size());
  };
  erase_all(" xmlns=\"http://www.w3.org/2000/svg\"");
  erase_all(" xmlns:xlink=\"http://www.w3.org/1999/xlink\"");
  erase_all("\n xmlns=\"http://www.w3.org/2000/svg\"");
  erase_all("\n xmlns:xlink=\"http://www.w3.org/1999/xlink\"");
  auto erase_element = [&](const std::string& open, const std::string& close) {
    const size_t a = svg.find(open);
    if (a == std::string::npos) return;
    const size_t b = svg.find(close, a);
    if (b != std::string::npos) svg.erase(a, b + close.size() - a);
  };
  erase_element("<title>", "</title>");
  erase_element("<desc>", "</desc>");
  auto replace_all = [&](const std::string& from, const std::string& to) {
    for (size_t k = 0; (k = svg.find(from, k)) != std::string::npos; k += to.size())
      svg.replace(k, from.size(), to);
  };
  replace_all("id='", "id='" + prefix);
  replace_all("id=\"", "id=\"" + prefix);
  replace_all("href='#", "href='#" + prefix);
  replace_all("href=\"#", "href=\"#" + prefix);
  replace_all("url(#", "url(#" + prefix);
  const size_t open_end = svg.find("<svg") + 4;
  svg.insert(open_end,
             " class=\"" + css_class + "\" role=\"img\" aria-label=\"" + esc(label) + "\"");
  while (!svg.empty() && (svg.back() == '\n' || svg.back() == ' ')) svg.pop_back();
  return svg;
}

const char* kCss = R"(
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;color:#1b1b1b;background:#fafafa;margin:0}
main{max-width:1120px;margin:0 auto;padding:18px 28px 60px;background:#ffffff}
h1{font-size:1.6em;margin:0.4em 0 0.2em}
h2{font-size:1.25em;margin-top:1.8em;border-bottom:2px solid #e3e3e3;padding-bottom:4px}
h3{font-size:1.05em;margin-top:1.3em}
p,li{line-height:1.45}
table{border-collapse:collapse;margin:8px 0 14px;font-size:0.92em}
th,td{border:1px solid #d6d6d6;padding:4px 8px;text-align:left;vertical-align:top}
th{background:#f1f3f5}
td.ok{color:#176b2c;font-weight:600}
td.bad{color:#b3261e;font-weight:600}
td.warn{color:#8a5a00}
.banner{padding:10px 14px;border-radius:6px;font-weight:600;margin:10px 0}
.banner.ok{background:#e6f4ea;border:1px solid #9ad0a8;color:#0f5223}
.banner.bad{background:#fdecea;border:1px solid #f1a7a1;color:#8c1d18}
.grid{display:flex;flex-wrap:wrap;gap:24px;align-items:flex-start}
.grid > div{flex:1 1 440px}
pre{background:#f4f4f4;border:1px solid #e0e0e0;padding:8px 10px;overflow-x:auto;white-space:pre-wrap;word-break:break-all}
figure{margin:12px 0 20px}
figcaption{font-size:0.9em;color:#444444;margin-top:4px}
svg.plot{width:100%;height:auto;display:block}
svg.narrow{max-width:720px}
svg.assembly{width:100%;max-width:780px;height:auto;display:block}
.noplot{border:1px dashed #b0b0b0;background:#fbfbfb;padding:14px;color:#555555}
.small{font-size:0.88em;color:#444444}
details{margin:10px 0}
summary{cursor:pointer;font-weight:600}
table.trials td,table.trials th{font-size:0.82em;padding:2px 5px;white-space:nowrap}
table.trials td:last-child{white-space:normal;min-width:220px}
.scroll{overflow-x:auto}
nav a{margin-right:12px}
)";

}  // namespace

// ---------------------------------------------------------------------------

Report make_report(const ReportInput& in, const ReportOptions& options) {
  Report report;
  const auto& S = in.summary;
  const Tolerances& tol = in.tolerances;
  const bool have_best = S.best_trial.particle_steps > 0.0;  // default-constructed: none
  const double s3 = in.lateral_stress;
  const std::string gnuplot = options.gnuplot.empty() ? "" : find_program(options.gnuplot);

  // ---- trial points ---------------------------------------------------------
  std::vector<Point> points;
  auto add_point = [&](const TrialRecord& t, const std::string& label) {
    Point p;
    p.label = label;
    p.phase = t.phase;
    p.trial = &t;
    p.cost = t.particle_steps;
    p.seconds = t.wall_time_s;
    if (!t.complete && t.steps_run > 0 && t.params.steps > t.steps_run)
      p.seconds *= static_cast<double>(t.params.steps) / static_cast<double>(t.steps_run);
    if (in.reference && t.complete && !t.diverged && t.criteria.peak_stress_yy < 0.0)
      p.peak_error =
          (in.reference->peak - t.criteria.peak_stress_yy) / std::abs(in.reference->peak);
    p.best = have_best && t.phase == S.best_trial.phase && t.id == S.best_trial.id &&
             t.params.steps == S.best_trial.params.steps;
    points.push_back(p);
  };
  for (const auto& t : S.trials) add_point(t, std::to_string(t.id));
  if (in.baseline)
    for (size_t k = 0; k < in.baseline->trials.size(); ++k)
      add_point(in.baseline->trials[k], "b" + std::to_string(k));
  if (in.reference) {
    add_point(in.reference->coarse, "r8");
    add_point(in.reference->fine, "r16");
  }
  std::optional<double> best_peak_error;
  for (const auto& p : points)
    if (p.best) best_peak_error = p.peak_error;
  // The paper-recipe result: the passing baseline trial.
  const Point* baseline_point = nullptr;
  for (const auto& p : points)
    if (p.phase == "baseline" && p.trial->passed) baseline_point = &p;

  Doc d;
  const std::string title = "demcal calibration report: " + in.scene;
  d.raw_html(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta "
      "name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
      esc(title) + "</title>\n<style>" + kCss + "</style>\n</head>\n<body>\n<main>\n");
  d.heading(1, title);
  d.raw_html(std::string("<div class=\"banner ") + (S.success ? "ok" : "bad") + "\">" +
             esc(std::string(S.success ? "SUCCESS" : "FAILURE") + ": " + S.message) + "</div>\n");
  d.md << "**" << (S.success ? "SUCCESS" : "FAILURE") << "**: " << S.message << "\n\n";
  {
    std::string line = "Scene " + in.scene + ", " + grouped(in.particles) + " particles (REV); " +
                       std::to_string(S.trials.size()) + " trials (" +
                       std::to_string(S.trials_run) + " run, " + std::to_string(S.trials_reused) +
                       " reused from an earlier run), strategy " + S.strategy + ", " +
                       num(S.wall_time_s, 3) + " s in this invocation. σ3 = " + kpa(s3) + ".";
    d.para(line, "small");
  }
  // At a glance: the answer and why to trust it, in four lines.
  {
    std::vector<std::string> glance;
    if (have_best) {
      glance.push_back(
          std::string(S.success ? "Use " : "Best found (not certified): ") + params_text(S.best) +
          " (" + num(static_cast<double>(S.best.steps) / std::max<double>(1, in.particles), 4) +
          " steps per particle) on the REV" +
          (in.prototype_particles > in.particles && in.particles > 0
               ? "; Nstep " +
                     grouped(std::llround(static_cast<double>(S.best.steps) *
                                          static_cast<double>(in.prototype_particles) /
                                          static_cast<double>(in.particles))) +
                     " for the " + grouped(in.prototype_particles) + "-particle prototype."
               : "."));
      const Ratios r = ratios(in.best ? in.best->score.criteria : S.best_trial.criteria, tol);
      glance.push_back("Every criterion within tolerance: worst " + r.worst_name() + " at " +
                       fixed(100.0 * r.worst(), 0) + " % of its tolerance.");
    }
    if (S.certificate.steps > 0)
      glance.push_back(
          "Convergence certificate " + std::string(S.certificate.passed ? "passed" : "FAILED") +
          ": Nstep doubled moves the peak by " + pct(S.certificate.steps_doubled_peak_change, 2) +
          ", Richardson error estimate " + pct(S.certificate.richardson_error, 2) +
          " against the " + pct(in.accuracy, 0) + " target.");
    if (in.reference && best_peak_error)
      glance.push_back("Against a converged reference (--evidence): peak error " +
                       signed_pct(*best_peak_error, 2) + ".");
    if (baseline_point && have_best)
      glance.push_back("The paper's recipe (α 0.2, ζ 1, Nstep doubled until it passes) costs " +
                       num(baseline_point->cost / std::max(1.0, S.best_trial.particle_steps), 3) +
                       "× as many particle-steps per run" +
                       (baseline_point->peak_error
                            ? " (peak error " + signed_pct(*baseline_point->peak_error, 2) + ")."
                            : "."));
    if (!glance.empty()) d.bullets(glance);
  }
  d.raw_html(
      "<nav class=\"small\"><a href=\"#answer\">answer</a><a href=\"#panels\">panels</a>"
      "<a href=\"#diagnosis\">diagnosis</a><a href=\"#history\">search history</a>"
      "<a href=\"#speed\">speed vs accuracy</a><a href=\"#upscaling\">upscaling</a>"
      "<a href=\"#assembly\">assembly</a><a href=\"#trials\">all trials</a></nav>\n");

  // ---- the answer -----------------------------------------------------------
  d.heading(2,
            S.success ? "The answer: calibrated parameters"
            : have_best
                ? "The answer: best parameters found, NOT certified (see the certificate below)"
                : "The answer: no parameter set passed",
            "answer");
  {
    const auto& P = in.params;
    auto get = [&](const char* block, const char* key) -> std::optional<double> {
      if (!P.is_object() || !P.contains(block) || !P[block].is_object()) return std::nullopt;
      const auto& b = P[block];
      if (!b.contains(key) || !b[key].is_number()) return std::nullopt;
      return b[key].get<double>();
    };
    auto cell = [&](const char* block, const char* key, int sig = 4) {
      const auto v = get(block, key);
      return v ? num(*v, sig) : std::string("n/a");
    };
    auto int_cell = [&](const char* block, const char* key) {
      const auto v = get(block, key);
      return v ? grouped(static_cast<int64_t>(std::llround(*v))) : std::string("n/a");
    };
    auto steps_cell = [&](const char* block) { return int_cell(block, "steps"); };
    auto time_cell = [&](const char* block) {
      const auto a = get(block, "steps"), b = get(block, "dt");
      return a && b ? num(*a * *b, 4) : std::string("n/a");
    };
    std::vector<std::vector<std::string>> rows{
        {"particles", "N", "-", int_cell("rev", "particles"), int_cell("prototype", "particles")},
        {"time step ratio", "α = Δt/Δt_crit", "-", cell("rev", "dt_ratio"),
         cell("prototype", "dt_ratio")},
        {"time step", "Δt", "s", cell("rev", "dt"), cell("prototype", "dt")},
        {"critical time step", "Δt_crit = 2·sqrt(m_min/kn)", "s", cell("rev", "dt_crit"),
         cell("prototype", "dt_crit")},
        {"loading steps", "Nstep", "-", steps_cell("rev"), steps_cell("prototype")},
        {"loading time", "Nstep·Δt", "s", time_cell("rev"), time_cell("prototype")},
        {"translational damping ratio", "ζ_t = D_t/D_t^crit", "-",
         cell("rev", "damping_ratio_translation"), cell("prototype", "damping_ratio_translation")},
        {"translational damping", "D_t (lightest particle)", "N·s/m",
         cell("rev", "damping_translation"), cell("prototype", "damping_translation")},
        {"rotational damping ratio", "ζ_r = D_r/D_r^crit", "-",
         cell("rev", "damping_ratio_rotation"), cell("prototype", "damping_ratio_rotation")},
        {"rotational damping", "D_r (lightest particle)", "N·m·s", cell("rev", "damping_rotation"),
         cell("prototype", "damping_rotation")},
        {"mass scaling", "f_ms", "-", cell("rev", "mass_scaling"),
         cell("prototype", "mass_scaling")}};
    d.table({"parameter", "symbol", "unit", S.success ? "REV (calibrated)" : "REV (best found)",
             "prototype (upscaled)"},
            rows);
    d.para(
        "Damping is per particle: every particle gets the same ratio ζ, D = ζ·D^crit with "
        "D_t^crit = 2·sqrt(kn·m) and D_r^crit = 2·sqrt(kt·r²·I) of that particle; the absolute "
        "values above are the lightest particle's. The prototype keeps the multipliers and "
        "scales Nstep with the particle count. The search never proposed α beyond " +
            (in.dt_ratio_max > 0 ? num(in.dt_ratio_max, 3) : std::string("n/a")) +
            " (0.95 of the stable α = " + num(S.dt_ratio_stable, 3) +
            " estimated from the contact stiffnesses, translation and rotation).",
        "small");

    d.heading(3, std::string("Criteria reached (") + (S.success ? "calibrated" : "best") +
                     " run) against their tolerances");
    if (have_best) {
      // The rerun's criteria (every field; a trial reloaded by --resume
      // carries only those trials.jsonl keeps). Same run, same numbers.
      const auto& c = in.best ? in.best->score.criteria : S.best_trial.criteria;
      auto row = [&](const std::string& name, const std::string& meaning, double v, double t) {
        return std::vector<std::string>{
            name, meaning, num(v, 3), num(t, 3), fixed(v / t, 2) + "×", v <= t ? "pass" : "FAIL"};
      };
      std::vector<std::vector<std::string>> rows{
          row("force balance", "max of the three below: max |trend| of b − σ", c.force_balance,
              tol.force_balance),
          row("  lateral xx", "(b_xx − σ_xx)/σ3", c.force_balance_xx, tol.force_balance),
          row("  vertical yy", "(b_yy − σ_yy)/max(|b_yy|, σ3)", c.force_balance_yy,
              tol.force_balance),
          row("  shear", "sym(b − σ)_xy/σ3", c.force_balance_shear, tol.force_balance),
          row("moment balance", "RMS (σ_xy − σ_yx)/σ3", c.moment_balance, tol.moment_balance),
          row("servo", "max |trend| (lateral wall stress − σ3)/σ3", c.servo, tol.servo),
          row("oscillation", "robust noise of the force-balance gaps", c.oscillation,
              tol.oscillation)};
      d.table({"criterion", "measure", "value", "tolerance", "value/tolerance", "verdict"}, rows);
      d.table(
          {"for comparison (not criteria)", "value"},
          {{"paper's force balance RMS(b_yy − σ_yy)/RMS(b_yy)", num(c.force_balance_paper, 3)},
           {"interior lateral stress error (σ_xx against σ3)", num(c.interior_lateral, 3)},
           {"zigzag (noise b_yy and σ_yy share)", num(c.zigzag, 3)},
           {"kinetic / elastic energy, max", num(c.kinetic_energy_ratio_max, 3)},
           {"unbalanced-force ratio, mean / max",
            num(c.unbalanced_force_ratio_mean, 3) + " / " + num(c.unbalanced_force_ratio_max, 3)},
           {"inertial number, max", num(c.inertial_number_max, 3)},
           {"peak b_yy", kpa(c.peak_stress_yy) + " at ε_yy = " + pct(c.peak_strain_yy, 3)},
           {"analytical peak (rotation locked, walled box)",
            in.analytical_peak ? kpa(*in.analytical_peak) : std::string("n/a")}});
    } else {
      d.para("No trial passed every criterion: there is no calibrated parameter set.");
    }

    d.heading(3, "Convergence certificate");
    const auto& C = S.certificate;
    // The doubled run as the search ran it (its Nstep rounded like every
    // trial's): the certificate trial with the same multipliers.
    int64_t doubled_steps = 2 * C.steps;
    for (const auto& t : S.trials)
      if (t.phase == "certificate" && t.params.dt_ratio == S.best.dt_ratio &&
          t.params.damping_ratio_translation == S.best.damping_ratio_translation &&
          t.params.damping_ratio_rotation == S.best.damping_ratio_rotation &&
          std::abs(static_cast<double>(t.params.steps) / static_cast<double>(2 * C.steps) - 1.0) <
              2e-3)
        doubled_steps = t.params.steps;
    if (C.steps > 0) {
      d.table({"check", "value"},
              {{"peak b_yy at Nstep = " + grouped(C.steps), kpa(C.peak)},
               {"peak b_yy at 2·Nstep = " + grouped(doubled_steps), kpa(C.peak_doubled)},
               {"change |P(N) − P(2N)|/|P(2N)|", pct(C.steps_doubled_peak_change, 3)},
               {"Richardson error estimate of P(N), 2 × change (error ∝ 1/Nstep)",
                pct(C.richardson_error, 3)},
               {"accuracy target", pct(in.accuracy, 2)},
               {"certificate", C.passed ? "pass" : "FAIL"}});
    } else {
      d.para("No certificate: no passing parameter set to certify.");
    }
    if (in.reference) {
      const auto& R = *in.reference;
      std::vector<std::vector<std::string>> rows{
          {"peak b_yy at 8·Nstep = " + grouped(R.coarse.params.steps),
           kpa(R.coarse.criteria.peak_stress_yy)},
          {"peak b_yy at 16·Nstep = " + grouped(R.fine.params.steps),
           kpa(R.fine.criteria.peak_stress_yy)},
          {"converged reference 2·P(16N) − P(8N)", kpa(R.peak)},
          {"calibrated peak error against the reference",
           best_peak_error ? signed_pct(*best_peak_error, 2) : std::string("n/a")},
          {"within the accuracy target",
           best_peak_error ? (std::abs(*best_peak_error) <= in.accuracy ? "yes" : "no")
                           : std::string("n/a")}};
      if (in.analytical_peak)
        rows.push_back(
            {"reference against the analytical peak (rotation locked)",
             signed_pct((*in.analytical_peak - R.peak) / std::abs(*in.analytical_peak), 1)});
      d.heading(3, "Evidence: converged reference (--evidence)");
      d.table({"check", "value"}, rows);
    }
    if (in.baseline) {
      const auto& B = *in.baseline;
      std::string text;
      if (B.passed && baseline_point) {
        text = "The paper's recipe done mechanically (α = 0.2, ζ_t = ζ_r = 1, Nstep doubled from " +
               grouped(B.trials.front().params.steps) +
               " until every criterion passes) passes at Nstep = " + grouped(B.params.steps) +
               ": " + sci(baseline_point->cost) + " particle-steps per run against " +
               sci(S.best_trial.particle_steps) + " calibrated (" +
               num(baseline_point->cost / std::max(1.0, S.best_trial.particle_steps), 3) +
               "× the cost)";
        if (baseline_point->peak_error)
          text += ", peak error " + signed_pct(*baseline_point->peak_error, 2) +
                  " against the reference";
        text += "; the recipe's search itself cost " + sci(B.particle_steps_total) +
                " particle-steps in " + std::to_string(B.trials.size()) + " trials.";
      } else {
        text = "The paper's recipe done mechanically (α = 0.2, ζ_t = ζ_r = 1, Nstep doubled " +
               std::to_string(B.trials.size()) + " times) never passed every criterion (" +
               sci(B.particle_steps_total) + " particle-steps spent).";
      }
      d.heading(3, "Evidence: the paper's recipe (--evidence)");
      d.para(text);
    }

    d.heading(3, "Reproduce");
    d.code(in.command);
    std::vector<std::string> items;
    if (P.is_object()) {
      if (P.contains("config_sha256"))
        items.push_back("config SHA-256 " + P["config_sha256"].get<std::string>());
      if (P.contains("seed")) items.push_back("seed " + P["seed"].dump());
      if (P.contains("version")) items.push_back("demcal " + P["version"].get<std::string>());
    }
    items.push_back(
        "the result does not depend on --jobs; --resume reuses every finished trial of "
        "DIR/trials.jsonl");
    d.bullets(items);
  }

  // ---- plots ---------------------------------------------------------------
  Plotter plot;
  std::vector<const ReportRun*> runs;
  if (in.start) runs.push_back(&*in.start);
  if (in.best) runs.push_back(&*in.best);
  const bool have_ref_series = in.reference && !in.reference->fine_series.empty();
  for (size_t k = 0; k < runs.size(); ++k)
    plot.files["run" + std::to_string(k) + ".dat"] = series_dat(runs[k]->run.series);
  if (have_ref_series) plot.files["ref.dat"] = series_dat(in.reference->fine_series);

  auto series_figure = [&](const std::string& name, const std::string& ylabel,
                           std::vector<std::tuple<int, std::string, std::string>> curves,
                           std::string extra, bool with_reference, const std::string& caption,
                           std::vector<double> include = {}) {
    if (runs.empty()) return;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, strain = 0.0;
    for (const auto* r : runs)
      for (const auto& p : r->run.series) strain = std::max(strain, -100.0 * p.strain_yy);
    for (double v : include) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    // Shared axes, except that a diverged run does not set them (its
    // values explode; it is clipped, and its panel says it diverged).
    bool any_finished = false;
    for (const auto* r : runs) any_finished = any_finished || !r->run.diverged;
    for (const auto* r : runs) {
      if (r->run.diverged && any_finished) continue;
      for (const auto& p : r->run.series)
        for (const auto& [c, t, s] : curves) {
          const double v = column(p, c);
          if (std::isfinite(v)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
          }
        }
    }
    std::ostringstream g;
    g << Plotter::terminal(1060, 370) << "set output '" << name << ".svg'\n"
      << Plotter::common() << "set multiplot layout 1," << runs.size() << "\n"
      << "set xlabel 'vertical strain −ε_{yy} [%]'\nset ylabel '" << ylabel << "'\n"
      << "set xrange [0:" << dat(strain > 0 ? strain : 1.0) << "]\nset yrange " << gp_range(lo, hi)
      << "\nset key top right\n"
      << extra;
    for (size_t k = 0; k < runs.size(); ++k) {
      g << "set title '"
        << (runs[k]->label == "start point" ? std::string("start point: ") : runs[k]->label + ": ")
        << params_gp(runs[k]->params) << (runs[k]->run.diverged ? "  (DIVERGED)" : "") << "'\n";
      g << "plot ";
      bool first = true;
      for (const auto& [c, t, s] : curves) {
        g << (first ? "" : ", ") << "'run" << k << ".dat' u 1:" << c << " w l " << s << " t '" << t
          << "'";
        first = false;
      }
      if (with_reference && have_ref_series && runs[k] == &*in.best)
        g << ", 'ref.dat' u 1:2 w l lw 1 dt 3 lc rgb '#333333' t 'N_{step} ×16 (near-converged)'";
      g << "\n";
    }
    g << "unset multiplot\nunset output\nreset\n";
    plot.figures.push_back({name, g.str(), caption});
  };
  const std::string servo_tol = dat(100.0 * tol.servo);
  series_figure(
      "fig_a", "compressive stress [kPa]",
      {{2, "−b_{yy} boundary", "lw 5 lc rgb '#9ecae1'"},
       {3, "−σ_{yy} homogenized", "lw 1.5 lc rgb '#08306b'"}},
      "set key bottom right\n", true,
      "(a) Vertical boundary stress b_yy and homogenized stress σ_yy against the vertical strain, "
      "compression positive, start point (left) and calibrated run (right), same axes. A static "
      "run has the two curves on top of each other; a gap means the particles are not in "
      "force balance (loading too fast, too much or too little damping).");
  series_figure(
      "fig_b", "shear stress [kPa] (tension positive)",
      {{4, "σ_{xy}", "lw 3 lc rgb '#fdae6b'"}, {5, "σ_{yx}", "lw 1.2 lc rgb '#7f2704'"}}, "", false,
      "(b) Off-diagonal homogenized stresses σ_xy and σ_yx. Moment balance means they coincide; "
      "large and opposite values mean rotational disequilibrium (time step too large, or "
      "rotational damping too high).");
  series_figure(
      "fig_lat", "lateral compressive stress [kPa]",
      {{6, "−b_{xx} boundary", "lw 5 lc rgb '#a1d99b'"},
       {7, "−σ_{xx} homogenized", "lw 1.5 lc rgb '#00441b'"}},
      "set arrow 1 from graph 0, first " + dat(s3 / 1e3) + " to graph 1, first " + dat(s3 / 1e3) +
          " nohead dt 2 lc rgb '#666666'\nset label 1 'σ_3' at graph 0.98, first " + dat(s3 / 1e3) +
          " right offset 0,-0.8 tc rgb '#666666'\n",
      false,
      "Lateral components: boundary stress b_xx and homogenized σ_xx against σ3 (dashed). Global "
      "damping that drags against the lateral expansion shows up as σ_xx above b_xx: extra "
      "confinement and an over-predicted peak.",
      {s3 / 1e3});
  series_figure(
      "fig_servo", "servo error (p_{lateral} − σ_3)/σ_3 [%]",
      {{8, "servo error", "lw 1.5 lc rgb '#54278f'"}},
      "set arrow 1 from graph 0, first " + servo_tol + " to graph 1, first " + servo_tol +
          " nohead dt 2 lc rgb '#b3261e'\nset arrow 2 from graph 0, first -" + servo_tol +
          " to graph 1, first -" + servo_tol + " nohead dt 2 lc rgb '#b3261e'\n",
      false,
      "Boundary-control (servo) error of the lateral walls: mean lateral wall stress against σ3, "
      "in %. Dashed: ± the servo tolerance (applied to the trend of this curve).",
      {-100.0 * tol.servo, 100.0 * tol.servo});

  // Search history.
  std::string history_missing;
  if (!S.trials.empty()) {
    std::ostringstream h, hp, hf, he, hd, hb;
    int64_t best_so_far = 0;
    bool any_ratio[4] = {false, false, false, false};
    for (const auto& t : S.trials) {
      const Ratios r = ratios(t.criteria, tol);
      const double rv[4] = {r.force_balance, r.moment_balance, r.servo, r.oscillation};
      h << t.id << ' ' << t.params.steps;
      for (int k = 0; k < 4; ++k) {
        const bool ok = !t.diverged && std::isfinite(rv[k]) && rv[k] > 0;
        any_ratio[k] = any_ratio[k] || ok;
        h << ' ' << (ok ? dat(rv[k]) : "?");
      }
      h << ' ' << dat(objective_of(t, tol)) << '\n';
      std::ostringstream& o = t.diverged ? hd : !t.complete ? he : t.passed ? hp : hf;
      o << t.id << ' ' << t.params.steps << '\n';
      if (t.passed && t.complete && (best_so_far == 0 || t.params.steps < best_so_far))
        best_so_far = t.params.steps;
      if (best_so_far > 0) hb << t.id << ' ' << best_so_far << '\n';
    }
    plot.files["hist.dat"] = h.str();
    std::ostringstream g;
    g << Plotter::terminal(1060, 760) << "set output 'fig_history.svg'\n"
      << Plotter::common()
      << "set multiplot layout 3,1\nset xrange [-0.5:" << S.trials.back().id + 0.5 << "]\n"
      << "set key outside right top\nset lmargin 12\nset rmargin 30\n";
    // Panel 1: Nstep per trial.
    g << "set logscale y\nset format y '%.0f'\nset ylabel 'N_{step} (cost)'\nset xlabel ''\n"
         "set title 'Trials in order: the loading steps tried and the cheapest passing so "
         "far'\nplot ";
    std::vector<std::string> clauses;
    auto add = [&](const std::string& file, const std::string& content, const std::string& clause) {
      if (content.empty()) return;
      plot.files[file] = content;
      clauses.push_back("'" + file + "' " + clause);
    };
    add("hist_best.dat", hb.str(),
        "u 1:2 w steps lw 2 lc rgb '#176b2c' t 'cheapest passing so far'");
    add("hist_pass.dat", hp.str(), "u 1:2 w p pt 7 ps 0.9 lc rgb '#2ca02c' t 'pass'");
    add("hist_fail.dat", hf.str(), "u 1:2 w p pt 6 ps 0.9 lc rgb '#d62728' t 'fail'");
    add("hist_early.dat", he.str(),
        "u 1:2 w p pt 4 ps 0.8 lc rgb '#ff7f0e' t 'stopped early (fail)'");
    add("hist_div.dat", hd.str(), "u 1:2 w p pt 2 ps 1.0 lc rgb '#000000' t 'diverged'");
    for (size_t k = 0; k < clauses.size(); ++k) g << (k ? ", " : "") << clauses[k];
    g << "\n";
    // Panel 2: criteria / tolerance.
    const char* names[4] = {"force balance", "moment balance", "servo", "oscillation"};
    const char* colours[4] = {"#1f77b4", "#9467bd", "#8c564b", "#e377c2"};
    const int pts[4] = {7, 5, 9, 13};
    g << "set format y '10^{%L}'\nset ylabel 'criterion / tolerance'\nset title 'Each criterion "
         "per trial, divided by its "
         "tolerance (≤ 1 passes)'\n"
         "set arrow 1 from graph 0, first 1 to graph 1, first 1 nohead lw 1.5 dt 2 lc rgb "
         "'#b3261e'\n";
    bool any = false;
    std::ostringstream p2;
    for (int k = 0; k < 4; ++k) {
      if (!any_ratio[k]) continue;
      p2 << (any ? ", " : "plot ") << "'hist.dat' u 1:" << 3 + k << " w lp lw 1 pt " << pts[k]
         << " ps 0.6 lc rgb '" << colours[k] << "' t '" << names[k] << "'";
      any = true;
    }
    g << (any ? p2.str() : std::string("plot 1 notitle")) << "\n";
    // Panel 3: the objective.
    g << "unset arrow 1\nunset logscale y\nset format y '%g'\nset yrange [0:3]\nset xlabel "
         "'trial'\nset ylabel 'objective'\n"
         "set title 'Search objective: passed = log_{10}(particle-steps)/20 (< 1), failed 1 to 2, "
         "diverged 2 to 3'\n"
         "set arrow 2 from graph 0, first 1 to graph 1, first 1 nohead dt 2 lc rgb '#888888'\n"
         "set arrow 3 from graph 0, first 2 to graph 1, first 2 nohead dt 2 lc rgb '#888888'\n"
         "plot 'hist.dat' u 1:7 w lp pt 7 ps 0.6 lw 1 lc rgb '#333333' t 'objective'\n";
    g << "unset multiplot\nunset output\nreset\n";
    plot.figures.push_back(
        {"fig_history", g.str(),
         "Search history. Top: Nstep of every trial (log), coloured by verdict, and the cheapest "
         "passing Nstep found so far. Middle: each criterion over its tolerance. Bottom: the "
         "objective the search minimises (every passing run beats every failing one)."});
  }

  // Speed against accuracy.
  {
    struct Cat {
      std::string file, clause;
      std::function<bool(const Point&)> in;
    };
    auto complete = [](const Point& p) { return p.trial->complete && !p.trial->diverged; };
    std::vector<Cat> cats{
        {"sp_fail.dat", "w p pt 6 ps 0.9 lc rgb '#d62728' t 'search trial, fail'",
         [&](const Point& p) {
           return complete(p) && !p.trial->passed && p.phase != "baseline" &&
                  p.phase != "reference";
         }},
        {"sp_early.dat", "w p pt 4 ps 0.7 lc rgb '#ff7f0e' t 'stopped early (error so far)'",
         [&](const Point& p) { return !p.trial->complete && !p.trial->diverged; }},
        {"sp_pass.dat", "w p pt 7 ps 0.9 lc rgb '#2ca02c' t 'search trial, pass'",
         [&](const Point& p) {
           return complete(p) && p.trial->passed && p.phase != "baseline" && p.phase != "reference";
         }},
        {"sp_base.dat",
         "w lp pt 9 ps 1.3 lw 1 dt 2 lc rgb '#e6550d' t 'paper recipe (Nstep doubled)'",
         [&](const Point& p) { return complete(p) && p.phase == "baseline"; }},
        {"sp_ref.dat", "w p pt 11 ps 1.3 lc rgb '#555555' t 'reference runs (8N, 16N)'",
         [&](const Point& p) { return complete(p) && p.phase == "reference"; }},
        {"sp_best.dat", "w p pt 3 ps 3 lw 2.5 lc rgb '#08519c' t 'chosen (calibrated)'",
         [&](const Point& p) { return p.best; }}};
    // y: force-balance error or |peak error|; x: particle-steps or seconds.
    auto yval = [](const Point& p, int which) -> double {
      if (which == 0) return p.trial->diverged ? NAN : p.trial->criteria.force_balance;
      return p.peak_error ? std::abs(*p.peak_error) : NAN;
    };
    auto xval = [](const Point& p, int which) { return which == 0 ? p.cost : p.seconds; };
    const int rows = in.reference ? 2 : 1;
    std::ostringstream g;
    g << Plotter::terminal(1060, rows == 2 ? 780 : 420) << "set output 'fig_speed.svg'\n"
      << Plotter::common() << "set multiplot layout " << rows << ",2\nset logscale xy\n"
      << "set format x '10^{%L}'\nset format y '10^{%L}'\nset key top right opaque "
         "font ',9'\n";
    bool drawn = false;
    for (int yr = 0; yr < rows; ++yr) {
      for (int xc = 0; xc < 2; ++xc) {
        std::vector<std::string> clauses;
        double ylo = std::numeric_limits<double>::infinity(), yhi = 0.0;
        for (const auto& c : cats) {
          std::ostringstream o;
          for (const auto& p : points) {
            if (!c.in(p)) continue;
            const double x = xval(p, xc), y = yval(p, yr);
            if (std::isfinite(x) && x > 0 && std::isfinite(y) && y > 0) {
              o << dat(x) << ' ' << dat(y) << '\n';
              ylo = std::min(ylo, y);
              yhi = std::max(yhi, y);
            }
          }
          if (o.str().empty()) continue;
          const std::string file = std::to_string(yr) + std::to_string(xc) + c.file;
          plot.files[file] = o.str();
          clauses.push_back("'" + file + "' u 1:2 " + c.clause);
        }
        // Pareto front: no other finished trial is both cheaper and more accurate.
        std::vector<std::pair<double, double>> xy;
        for (const auto& p : points) {
          if (!complete(p)) continue;
          const double x = xval(p, xc), y = yval(p, yr);
          if (std::isfinite(x) && x > 0 && std::isfinite(y) && y > 0) xy.push_back({x, y});
        }
        std::sort(xy.begin(), xy.end());
        std::ostringstream front;
        double ymin = std::numeric_limits<double>::infinity();
        for (const auto& [x, y] : xy)
          if (y < ymin) {
            ymin = y;
            front << dat(x) << ' ' << dat(y) << '\n';
          }
        if (!front.str().empty()) {
          const std::string file = std::to_string(yr) + std::to_string(xc) + "sp_front.dat";
          plot.files[file] = front.str();
          clauses.insert(clauses.begin(),
                         "'" + file + "' u 1:2 w steps lw 6 lc rgb '#fdd0a2' t 'Pareto front'");
        }
        const double limit = yr == 0 ? tol.force_balance : in.accuracy;
        if (yhi > 0) {
          // Whole decades, with headroom above the data for the key.
          ylo = std::pow(10.0, std::floor(std::log10(std::min(ylo, limit))));
          yhi = std::pow(10.0, std::ceil(std::log10(std::max(yhi, limit)) + 1.2));
          g << "set yrange [" << dat(ylo) << ":" << dat(yhi) << "]\n";
        } else {
          g << "set autoscale y\n";
        }
        g << "set xlabel '" << (xc == 0 ? "cost [particle-steps]" : "cost [s wall time]") << "'\n"
          << "set ylabel '"
          << (yr == 0 ? "force-balance error (criterion)" : "|peak error| vs converged reference")
          << "'\nset title '" << (yr == 0 ? "force-balance error" : "peak error")
          << " against cost in " << (xc == 0 ? "particle-steps" : "seconds") << "'\n"
          << "set arrow 1 from graph 0, first " << dat(limit) << " to graph 1, first " << dat(limit)
          << " nohead dt 2 lw 1.5 lc rgb '#b3261e'\n"
          << "set label 1 '" << (yr == 0 ? "tolerance" : "accuracy target")
          << "' at graph 0.98, first " << dat(limit)
          << " right offset 0,-0.7 tc rgb '#b3261e' font ',9'\n";
        if (clauses.empty()) {
          g << "unset logscale xy\nset xrange [0:1]\nset yrange [0:1]\nunset arrow 1\nunset label "
               "1\n"
               "set label 2 'no finished trial' at 0.5,0.5 center\nplot -1 notitle\n"
               "set logscale xy\nset autoscale\nunset label 2\n";
        } else {
          g << "plot ";
          for (size_t k = 0; k < clauses.size(); ++k) g << (k ? ", " : "") << clauses[k];
          g << "\n";
          drawn = true;
        }
      }
    }
    g << "unset multiplot\nunset output\nreset\n";
    if (drawn || !points.empty())
      plot.figures.push_back(
          {"fig_speed", g.str(),
           std::string("Speed against accuracy: every trial's cost (particle-steps planned, and "
                       "wall seconds, extrapolated to the full run for trials stopped early) "
                       "against its force-balance error") +
               (in.reference ? " (top) and its peak error against the converged reference "
                               "(bottom, finished trials)"
                             : "") +
               ". The shaded staircase is the Pareto front (no finished trial is both cheaper "
               "and more accurate; a failing trial can sit on it when it failed another "
               "criterion); "
               "the star is the chosen parameter set" +
               (in.baseline
                    ? "; orange triangles joined by a dashed line, the paper's recipe with Nstep "
                      "doubled"
                    : "") +
               ". Wall seconds are noisy: trials ran in parallel on shared cores."});
  }

  // Upscaling line.
  const bool upscale = have_best && in.prototype_particles > in.particles && in.particles > 0;
  int64_t proto_steps = 0;
  if (have_best && in.particles > 0) {
    proto_steps = std::llround(static_cast<double>(S.best.steps) *
                               static_cast<double>(std::max(in.prototype_particles, in.particles)) /
                               static_cast<double>(in.particles));
    if (in.params.is_object() && in.params.contains("prototype") &&
        in.params["prototype"].contains("steps"))
      proto_steps = in.params["prototype"]["steps"].get<int64_t>();
  }
  if (upscale) {
    const double n0 = static_cast<double>(in.particles),
                 n1 = static_cast<double>(in.prototype_particles);
    const double per = static_cast<double>(S.best.steps) / n0;
    const double a = n0 / 3.0, b = n1 * 3.0;
    plot.files["up_line.dat"] =
        dat(a) + ' ' + dat(per * a) + '\n' + dat(b) + ' ' + dat(per * b) + '\n';
    plot.files["up_pts.dat"] = dat(n0) + ' ' + dat(static_cast<double>(S.best.steps)) + '\n' +
                               dat(n1) + ' ' + dat(static_cast<double>(proto_steps)) + '\n';
    std::ostringstream g;
    g << Plotter::terminal(760, 400) << "set output 'fig_upscale.svg'\n"
      << Plotter::common() << "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
      << "set xlabel 'particles N'\nset ylabel 'N_{step}'\nset key top left\n"
      << "set xrange [" << dat(a) << ":" << dat(b) << "]\n"
      << "set label 1 'REV' at first " << dat(n0) << ", first "
      << dat(static_cast<double>(S.best.steps)) << " offset 1,-1\n"
      << "set label 2 'prototype' at first " << dat(n1) << ", first "
      << dat(static_cast<double>(proto_steps)) << " right offset -1,1\n"
      << "set title 'N_{step} = " << num(per, 4) << " · N (linear in the particle count)'\n"
      << "plot 'up_line.dat' u 1:2 w l lw 2 lc rgb '#3182bd' t 'upscaling line', "
         "'up_pts.dat' u 1:2 w p pt 7 ps 1.8 lc rgb '#08306b' t 'REV and prototype'\n"
      << "unset output\nreset\n";
    plot.figures.push_back({"fig_upscale", g.str(),
                            "Upscaling: the multipliers do not depend on size; Nstep grows "
                            "linearly with the particle count (Tu & Andrade)."});
  }

  // Render.
  std::map<std::string, std::string> svgs;
  std::string plot_error;
  if (gnuplot.empty()) {
    report.plot_status = options.gnuplot.empty()
                             ? "plots not rendered (disabled)"
                             : "plots not rendered: gnuplot was not found; every number is in "
                               "the tables. To get the plots: apt-get install gnuplot-nox, then "
                               "rerun the same command with --resume (it reuses every trial)";
  } else if (!plot.figures.empty()) {
    std::string script;
    std::vector<std::string> outputs;
    for (const auto& f : plot.figures) {
      script += f.script;
      outputs.push_back(f.name + ".svg");
    }
    auto got = run_gnuplot(gnuplot, script, plot.files, outputs, &plot_error);
    // A failed figure stops gnuplot's script: render the missing ones alone.
    for (const auto& f : plot.figures) {
      if (got.count(f.name + ".svg")) continue;
      auto one = run_gnuplot(gnuplot, f.script, plot.files, {f.name + ".svg"}, &plot_error);
      got.insert(one.begin(), one.end());
    }
    int k = 0;
    for (const auto& f : plot.figures) {
      auto it = got.find(f.name + ".svg");
      if (it != got.end())
        svgs[f.name] = inline_svg(it->second, "g" + std::to_string(k) + "-", f.name,
                                  f.name == "fig_upscale" ? "plot narrow" : "plot");
      ++k;
    }
    report.plots = svgs.size() == plot.figures.size();
    report.plot_status = report.plots ? std::string("plots rendered by gnuplot")
                                      : "some plots failed: " + plot_error;
  }
  auto fig = [&](const std::string& name) {
    for (const auto& f : plot.figures)
      if (f.name == name) {
        auto it = svgs.find(name);
        d.figure(it == svgs.end() ? "" : it->second, f.caption,
                 gnuplot.empty()
                     ? "Plot not rendered: gnuplot is not installed. Every number is in "
                       "the tables of this report. To get the plots: apt-get install "
                       "gnuplot-nox, then rerun the same command with --resume (every "
                       "trial is reused)."
                     : "Plot not rendered: " + plot_error);
        return;
      }
  };

  // ---- panels ---------------------------------------------------------------
  d.heading(2, "Start point and result: the paper's panels", "panels");
  if (runs.empty()) {
    d.para("No runs with series were recorded.");
  } else {
    std::string intro = "Each run below was rerun with its whole series (" +
                        std::to_string(runs.empty() ? 0 : runs[0]->run.series.size()) +
                        " monitoring points).";
    if (in.start)
      intro += " Start point: " + params_text(in.start->params) +
               " (the paper's recommended multipliers with a size-based Nstep of " +
               grouped(in.particles > 0 ? in.start->params.steps / in.particles : 0) +
               " per particle, where the search starts).";
    if (in.best) intro += " Calibrated: " + params_text(in.best->params) + ".";
    d.para(intro);
    fig("fig_a");
    fig("fig_b");
    fig("fig_lat");
    fig("fig_servo");
    // The same facts as numbers.
    std::vector<std::string> head{"measure"};
    for (const auto* r : runs) head.push_back(r->label);
    if (have_ref_series) head.push_back("Nstep ×16");
    std::vector<std::vector<std::string>> rows;
    struct Facts {
      double peak, peak_strain, max_gap_yy, max_gap_xx, max_asym, max_servo;
      Criteria c;
      bool diverged;
    };
    auto facts = [&](const std::vector<MonitorPoint>& s, const Criteria& c, bool diverged) {
      Facts f{0, 0, 0, 0, 0, 0, c, diverged};
      const Peak pk = find_peak(s);
      f.peak = pk.stress_yy;
      f.peak_strain = pk.strain_yy;
      for (size_t k = 1; k < s.size(); ++k) {
        const auto& p = s[k];
        f.max_gap_yy = std::max(f.max_gap_yy, std::abs(p.b(1, 1) - p.sigma(1, 1)));
        f.max_gap_xx = std::max(f.max_gap_xx, std::abs(p.b(0, 0) - p.sigma(0, 0)));
        f.max_asym = std::max(f.max_asym, std::abs(p.sigma(0, 1) - p.sigma(1, 0)));
        f.max_servo = std::max(f.max_servo, std::abs(p.lateral_stress_error));
      }
      return f;
    };
    std::vector<Facts> fs;
    for (const auto* r : runs)
      fs.push_back(facts(r->run.series, r->score.criteria, r->run.diverged));
    if (have_ref_series)
      fs.push_back(facts(in.reference->fine_series, in.reference->fine.criteria, false));
    auto row = [&](const std::string& name, const std::function<std::string(const Facts&)>& f) {
      std::vector<std::string> r{name};
      for (const auto& x : fs) r.push_back(f(x));
      rows.push_back(r);
    };
    row("peak b_yy (monitoring points)", [](const Facts& f) { return kpa(f.peak); });
    row("strain at the peak", [](const Facts& f) { return pct(f.peak_strain, 3); });
    row("max |b_yy − σ_yy|", [](const Facts& f) { return kpa(f.max_gap_yy); });
    row("max |b_xx − σ_xx|", [](const Facts& f) { return kpa(f.max_gap_xx); });
    row("max |σ_xy − σ_yx|", [](const Facts& f) { return kpa(f.max_asym); });
    row("max |servo error|", [](const Facts& f) { return pct(f.max_servo, 3); });
    row("force balance (criterion)", [](const Facts& f) { return num(f.c.force_balance, 3); });
    row("moment balance (criterion)", [](const Facts& f) { return num(f.c.moment_balance, 3); });
    row("servo (criterion)", [](const Facts& f) { return num(f.c.servo, 3); });
    row("oscillation (criterion)", [](const Facts& f) { return num(f.c.oscillation, 3); });
    row("diverged", [](const Facts& f) { return std::string(f.diverged ? "diverged" : "no"); });
    // "no" would colour red: say it plainly.
    rows.back()[0] = "diverged?";
    for (size_t k = 1; k < rows.back().size(); ++k)
      if (rows.back()[k] == "no") rows.back()[k] = "did not diverge";
    d.table(head, rows);
  }

  // ---- diagnosis -----------------------------------------------------------
  d.heading(2, "Diagnosis in words", "diagnosis");
  if (in.start) {
    const auto& s = in.start->score;
    const Ratios r = ratios(s.criteria, tol);
    std::string text = "Start point (" + params_text(in.start->params) + "): " +
                       (s.passed ? "passes every criterion. "
                                 : "does not pass (worst: " + r.worst_name() + " at " +
                                       fixed(r.worst(), 2) + "× its tolerance). ") +
                       sentence(s.diagnosis.message);
    if (!s.diagnosis.signature.empty() && s.diagnosis.parameter != "none")
      text += " Signature: " + sentence(s.diagnosis.signature);
    d.para(text);
  }
  if (in.best) {
    const auto& s = in.best->score;
    d.para((S.success ? "Calibrated run: " : "Best run found (not certified): ") +
           std::string(s.passed ? "passes every criterion" : "does not pass") +
           (s.diagnosis.message.empty() ? "." : ". " + sentence(s.diagnosis.message)));
  }
  if (have_best) {
    // Rejected neighbourhoods: the failed trials nearest to the result.
    const double a_span = std::max(0.05, in.dt_ratio_max > 0 ? in.dt_ratio_max : 0.3);
    auto dist = [&](const AlgorithmSpec& p) {
      const auto& b = S.best;
      const double da = (p.dt_ratio - b.dt_ratio) / a_span;
      const double dn = std::log10(static_cast<double>(p.steps) / static_cast<double>(b.steps)) /
                        std::log10(400.0);
      const double dt = (p.damping_ratio_translation - b.damping_ratio_translation) / 4.0;
      const double dr = (p.damping_ratio_rotation - b.damping_ratio_rotation) / 4.0;
      return std::sqrt(da * da + dn * dn + dt * dt + dr * dr);
    };
    std::vector<std::pair<double, const TrialRecord*>> failed;
    for (const auto& t : S.trials)
      if (!t.passed) failed.push_back({dist(t.params), &t});
    std::stable_sort(failed.begin(), failed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    if (failed.size() > static_cast<size_t>(options.near_failures))
      failed.resize(options.near_failures);
    if (failed.empty()) {
      d.para("No trial failed: there is no rejected neighbourhood to describe.");
    } else {
      d.para(
          "Rejected neighbourhoods: the failed trials nearest to the result (distance in the "
          "search space normalised by its ranges), what differs from the result, and why they "
          "failed.");
      auto differs = [&](const AlgorithmSpec& p) {
        const auto& b = S.best;
        std::vector<std::string> parts;
        auto rel = [](double v, double ref) { return ref != 0 ? (v - ref) / std::abs(ref) : 0.0; };
        if (std::abs(rel(static_cast<double>(p.steps), static_cast<double>(b.steps))) > 0.005)
          parts.push_back(
              "Nstep " + grouped(p.steps) + " (" +
              signed_pct(rel(static_cast<double>(p.steps), static_cast<double>(b.steps)), 0) + ")");
        if (std::abs(p.dt_ratio - b.dt_ratio) > 0.0005)
          parts.push_back("α " + num(p.dt_ratio, 3) + " (result " + num(b.dt_ratio, 3) + ")");
        if (std::abs(p.damping_ratio_translation - b.damping_ratio_translation) > 0.005)
          parts.push_back("ζ_t " + num(p.damping_ratio_translation, 3) + " (result " +
                          num(b.damping_ratio_translation, 3) + ")");
        if (std::abs(p.damping_ratio_rotation - b.damping_ratio_rotation) > 0.005)
          parts.push_back("ζ_r " + num(p.damping_ratio_rotation, 3) + " (result " +
                          num(b.damping_ratio_rotation, 3) + ")");
        std::string out;
        for (size_t k = 0; k < parts.size(); ++k) out += (k ? ", " : "") + parts[k];
        return out.empty() ? std::string("same parameters") : out;
      };
      std::vector<std::vector<std::string>> rows;
      for (const auto& [dd, t] : failed) {
        const Ratios r = ratios(t->criteria, tol);
        rows.push_back({std::to_string(t->id), differs(t->params), verdict(*t),
                        t->diverged ? "diverged" : r.worst_name() + " " + fixed(r.worst(), 2) + "×",
                        t->diagnosis.empty() ? "(no diagnosis recorded)" : sentence(t->diagnosis)});
      }
      d.table({"trial", "differs from the result in", "verdict", "worst criterion / tolerance",
               "diagnosis"},
              rows);
    }
  }

  // ---- history, speed, upscaling --------------------------------------------
  d.heading(2, "Search history", "history");
  if (S.trials.empty()) {
    d.para("No trials.");
  } else {
    int pass = 0, fail = 0, early = 0, div = 0;
    for (const auto& t : S.trials) {
      if (t.diverged)
        ++div;
      else if (!t.complete)
        ++early;
      else if (t.passed)
        ++pass;
      else
        ++fail;
    }
    d.para(std::to_string(S.trials.size()) + " trials: " + std::to_string(pass) + " passed, " +
           std::to_string(fail) + " failed, " + std::to_string(early) +
           " stopped early (certain failures), " + std::to_string(div) +
           " diverged. Every trial with its criteria is in the table at the end and in "
           "DIR/trials.jsonl.");
    fig("fig_history");
  }

  d.heading(2, "Speed against accuracy", "speed");
  {
    std::string intro =
        "What each trial costs against how far from static it was. The chosen point is the "
        "cheapest trial that passes every criterion and the convergence certificate.";
    if (!in.reference)
      intro +=
          " Peak errors against a converged reference are measured with --evidence (it "
          "runs the calibrated multipliers at 8× and 16× Nstep, and the paper's recipe).";
    d.para(intro);
    fig("fig_speed");
    // The Pareto front in numbers (force-balance error against particle-steps).
    std::vector<const Point*> fin;
    for (const auto& p : points)
      if (p.trial->complete && !p.trial->diverged && p.trial->criteria.force_balance > 0)
        fin.push_back(&p);
    std::stable_sort(fin.begin(), fin.end(), [](const Point* a, const Point* b) {
      return a->cost < b->cost || (a->cost == b->cost && a->trial->criteria.force_balance <
                                                             b->trial->criteria.force_balance);
    });
    std::vector<std::vector<std::string>> rows;
    double ymin = std::numeric_limits<double>::infinity();
    for (const Point* p : fin) {
      if (p->trial->criteria.force_balance >= ymin) continue;
      ymin = p->trial->criteria.force_balance;
      rows.push_back({p->label + (p->best ? " (chosen)" : ""), p->phase,
                      params_text(p->trial->params), sci(p->cost), num(p->seconds, 3),
                      num(p->trial->criteria.force_balance, 3), verdict(*p->trial),
                      p->peak_error ? signed_pct(*p->peak_error, 2) : "n/a"});
    }
    d.heading(3, "Pareto front (force-balance error against particle-steps)");
    d.table({"trial", "phase", "parameters", "particle-steps", "seconds", "force balance",
             "verdict", "peak error vs reference"},
            rows);
    std::vector<std::vector<std::string>> marks;
    for (const auto& p : points)
      if (p.best || &p == baseline_point)
        marks.push_back({p.best ? "chosen (calibrated)" : "paper recipe", p.label,
                         params_text(p.trial->params), sci(p.cost), num(p.seconds, 3),
                         num(p.trial->criteria.force_balance, 3),
                         p.peak_error ? signed_pct(*p.peak_error, 2) : "n/a"});
    if (!marks.empty()) {
      d.heading(3, "Highlighted points");
      d.table({"point", "trial", "parameters", "particle-steps", "seconds", "force balance",
               "peak error vs reference"},
              marks);
    }
  }

  d.heading(2, "Upscaling to the prototype", "upscaling");
  if (!have_best) {
    d.para("No calibrated Nstep to upscale.");
  } else if (!upscale) {
    d.para(
        "No prototype larger than the REV is configured (prototype.particles): the REV "
        "parameters are the answer. With a prototype, Nstep_prototype = Nstep_REV · "
        "N_prototype / N_REV and the multipliers stay.");
  } else {
    d.para("Nstep_prototype = Nstep_REV · N_prototype / N_REV = " + grouped(S.best.steps) + " · " +
           grouped(in.prototype_particles) + " / " + grouped(in.particles) + " = " +
           grouped(proto_steps) + " (" +
           num(static_cast<double>(S.best.steps) / static_cast<double>(in.particles), 4) +
           " steps per particle); α, ζ_t and ζ_r are kept (they do not depend on size).");
    fig("fig_upscale");
  }

  // ---- assembly ------------------------------------------------------------
  d.heading(2, "The assembly at the peak", "assembly");
  if (in.picture) {
    const auto& p = *in.picture;
    double fmax = 0, tmax = 0;
    int pp = 0, pw = 0;
    for (const auto& f : p.forces) {
      fmax = std::max(fmax, f.fn);
      (f.wall ? pw : pp)++;
    }
    for (double t : p.rotation) tmax = std::max(tmax, std::abs(t));
    const std::string caption =
        "Calibrated run at its peak (step " + grouped(p.step) + " of " + grouped(p.steps) +
        ", ε_yy = " + pct(p.strain_yy, 3) + ", b_yy = " + kpa(p.stress_yy) +
        "): " + std::to_string(p.x.size()) +
        " disks coloured by their rotation since the start of "
        "loading (red counter-clockwise, blue clockwise, largest " +
        num(tmax * 180.0 / std::numbers::pi, 3) + "°); " + std::to_string(pp) +
        " particle contacts (black) and " + std::to_string(pw) +
        " wall contacts (brown), line width proportional to the normal force (largest " +
        num(fmax, 3) + " N).";
    d.html << "<figure>\n"
           << assembly_svg(p) << "\n<figcaption>" << esc(caption) << "</figcaption>\n</figure>\n";
    d.md << caption << " (picture in report.html)\n\n";
  } else {
    d.para("No picture: there is no calibrated run.");
  }

  // ---- all trials -----------------------------------------------------------
  d.heading(2, "All trials", "trials");
  {
    std::vector<std::vector<std::string>> rows;
    for (const auto& p : points) {
      const auto& t = *p.trial;
      const Ratios r = ratios(t.criteria, tol);
      auto ratio = [&](double v) { return t.diverged ? std::string("-") : fixed(v, 2); };
      rows.push_back({p.label + (p.best ? "*" : ""), t.phase, num(t.params.dt_ratio, 4),
                      grouped(t.params.steps), num(t.params.damping_ratio_translation, 3),
                      num(t.params.damping_ratio_rotation, 3), verdict(t), ratio(r.force_balance),
                      ratio(r.moment_balance), ratio(r.servo), ratio(r.oscillation),
                      t.complete && !t.diverged ? num(t.criteria.peak_stress_yy / 1e3, 4) : "-",
                      p.peak_error ? signed_pct(*p.peak_error, 2) : "-", sci(p.cost),
                      num(t.wall_time_s, 3), num(objective_of(t, tol), 4), sentence(t.diagnosis)});
    }
    d.para(
        "Criteria are divided by their tolerances (≤ 1 passes). * marks the chosen trial; b: "
        "paper-recipe trials, r8/r16: the reference runs (--evidence). Seconds are as run "
        "(trials stopped early ran only part of the loading).");
    d.details_begin("Show all " + std::to_string(points.size()) + " trials");
    d.table({"trial", "phase", "α", "Nstep", "ζ_t", "ζ_r", "verdict", "FB/tol", "MB/tol",
             "servo/tol", "osc/tol", "peak b_yy [kPa]", "peak error", "particle-steps", "s",
             "objective", "diagnosis"},
            rows, "trials");
    d.details_end();
  }

  d.para("Generated by demcal " + std::string(DEMCAL_VERSION) + "; " + report.plot_status + ".",
         "small");
  d.raw_html("</main>\n</body>\n</html>\n");
  report.html = d.html.str();
  report.markdown = d.md.str();
  return report;
}

}  // namespace demcal
