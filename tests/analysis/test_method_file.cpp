// Method files (include/nystrom/analysis/method_file.hpp) and `file:PATH` in resolve_method: round trip,
// integration equal to the catalog method, strict validation with clear errors.
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>

#include "nystrom/analysis/method_file.hpp"
#include "nystrom/nystrom.hpp"

using namespace nystrom;
using namespace nystrom::analysis;

namespace {

// `file:PATH` specifications need the reader, registered explicitly as the tool and the module do.
const bool reader_registered = (register_method_file_reader(), true);

std::filesystem::path temp_file(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("nystrom-mf-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}
std::string write(const std::string& name, const std::string& text) {
  const auto p = temp_file(name);
  std::ofstream(p) << text;
  return p.string();
}
SplittingScheme<bigcomplex> scheme_of(const std::string& name) {
  return std::get<SplittingScheme<bigcomplex>>(resolve_method(name).build());
}
std::string error_of(const std::string& path) {
  try {
    read_method_file(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

const std::string kVerlet = "name pv\norder 2\ndrift 1/2\nkick 1\ndrift 1/2\n";

}  // namespace

TEST(MethodFile, RoundTripOfAClosedFormMethod) {
  BigPrecision guard(256);
  const auto path =
      write("fr.txt", format_method_file("FR-file", 4, "Forest & Ruth (1990)", "test copy of FR", scheme_of("FR"), 40));
  const auto f = read_method_file(path);
  EXPECT_EQ(f.name, "FR-file");
  EXPECT_EQ(f.order, 4);
  EXPECT_EQ(f.steps.size(), 7u);
  EXPECT_GE(f.min_digits, 38);
  const auto d = resolve_method("file:" + path);
  EXPECT_EQ(d.info.name, "FR-file");
  EXPECT_EQ(d.info.order, 4);
  EXPECT_EQ(d.info.family, "splitting");
  EXPECT_TRUE(d.info.symmetric);
  EXPECT_TRUE(d.info.symplectic);
  EXPECT_EQ(d.info.forces_per_step, 3);
  // the coefficients agree with the catalog to 40 digits, so the integrations agree in long double exactly
  // up to the last bit or two
  using V = std::array<long double, 2>;
  auto a = make_integrator<V>(d, KeplerForce{});
  auto b = make_integrator<V>(resolve_method("FR"), KeplerForce{});
  const KeplerProblem<long double> p(0.5L);
  auto sa = p.initial_state(), sb = p.initial_state();
  a.integrate(sa, 0.01L, 700);
  b.integrate(sb, 0.01L, 700);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(static_cast<double>(sa.q[i] - sb.q[i]), 0.0, 1e-16);
    EXPECT_NEAR(static_cast<double>(sa.v[i] - sb.v[i]), 0.0, 1e-16);
  }
}

TEST(MethodFile, ComplexMethodRoundTripKeepsItsErrorTerms) {
  BigPrecision guard(256);
  // AC1 is published with 16-17 digits: write it with 17 so the file claims no more than it has
  const auto path = write("ac1.txt", format_method_file("AC1-copy", 5, "", "", scheme_of("AC1"), 17));
  const auto d = resolve_method("file:" + path);
  EXPECT_FALSE(d.info.symplectic);  // complex coefficients
  EXPECT_TRUE(d.info.complex);
  AnalysisOptions opt;
  opt.degree = 6;
  const auto a = analyze_method(d, opt);
  const auto b = analyze_method(resolve_method("AC1"), opt);
  EXPECT_EQ(a.order, 5);
  EXPECT_NEAR(a.degrees[5].norm, b.degrees[5].norm, 1e-15);
}

TEST(MethodFile, ExactRationalsAndComments) {
  const auto path = write("pv.txt", "# position Verlet\n\n" + kVerlet + "source test  # trailing comment\n");
  const auto f = read_method_file(path);
  EXPECT_EQ(f.min_digits, 0);
  EXPECT_EQ(f.source, "test");
  const auto d = resolve_method("file:" + path);
  EXPECT_EQ(d.info.forces_per_step, 1);
  AnalysisOptions opt;
  opt.degree = 3;
  EXPECT_TRUE(analyze_method(d, opt).exact);
}

TEST(MethodFile, RejectsBadFilesWithClearErrors) {
  struct Case {
    std::string text, message;
  };
  const std::vector<Case> cases{
      {"order 2\ndrift 1/2\nkick 1\ndrift 1/2\n", "missing 'name'"},
      {"name x\ndrift 1/2\nkick 1\ndrift 1/2\n", "missing 'order'"},
      {"name x\norder 2\n", "no 'drift'/'kick'"},
      {"name x\nname y\n" + kVerlet.substr(7), "given twice"},
      {"name two words\norder 2\n", "one token"},
      {"name x\norder 0\n", "between 1 and"},
      {"name x\norder 13\n", "between 1 and"},
      {"name x\norder five\n", "must be an integer"},
      {"name x\norder 2\ndrift 1/2\nkick 1.2.3\n", "malformed number '1.2.3'"},
      {"name x\norder 2\ndrift 1/2\nkick\n", "needs one or two numbers"},
      {"name x\norder 2\ndrift 1/2\nkick 1 0 0\n", "needs one or two numbers"},
      {"name x\norder 2\ndrift 1/0\nkick 1\ndrift 1/2\n", "zero denominator"},
      {"name x\norder 2\ndrift nan\nkick 1\n", "malformed number 'nan'"},
      {"name x\norder 2\ndrift 1/2\nkick -inf\ndrift 1/2\n", "malformed number '-inf'"},
      {"name x\norder 2\ndrift 1/2\nkick 0x1p0\ndrift 1/2\n", "malformed number '0x1p0'"},
      {"name x\norder 2\ndrift 1/2\nkick 1e\ndrift 1/2\n", "malformed number '1e'"},
      {"name x\norder 2\ndrift 1/2\nkick 1 1e999999999999\ndrift 1/2\n", "not finite"},
      {"name x\norder 2\ndrift 0.5\nkick 1e99999\ndrift 0.5\n", "sum to"},
      {"", "missing 'name'"},
      {"name x\norder 2\ndrift 1/2 kick 1\n", "needs one or two numbers"},
      {"name x\norder 2\nstep 1\n", "unknown keyword 'step'"},
      {"name x\norder 2\ndrift 1/2\nkick 1\ndrift 1/3\n", "sum to"},
      {"name x\norder 2\ndrift 1\n", "at least one drift and one kick"},
      {"name x\norder 3\ndrift 1/2\nkick 1\ndrift 1/2\n", "declares order 3 but the degree-3 error terms"},
      {"name x\norder 2\ndrift 1\nkick 1\n", "declares order 2 but the degree-2 error terms"},
  };
  int k = 0;
  for (const auto& c : cases) {
    const auto msg = error_of(write("bad" + std::to_string(k++) + ".txt", c.text));
    EXPECT_NE(msg.find(c.message), std::string::npos) << "file:\n" << c.text << "error: " << msg;
    EXPECT_NE(msg.find("method file"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "the error is one line: " << msg;
  }
  // a folder is not a method file
  EXPECT_THROW(read_method_file(temp_file("").string()), std::invalid_argument);
  EXPECT_NE(error_of("/nonexistent/method.txt").find("cannot read method file"), std::string::npos);
  // a device is refused before anything is read (/dev/zero would never end)
  EXPECT_NE(error_of("/dev/zero").find("it is a device"), std::string::npos);
  EXPECT_THROW(resolve_method("file:/nonexistent/method.txt"), invalid_input);
}

TEST(MethodFile, DeclaredOrderIsCheckedAgainstTheDigitsGiven) {
  BigPrecision guard(256);
  // AR1 with one coefficient changed in the 10th digit: fine at order 5 with 8 digits, rejected with 17 digits.
  auto s = scheme_of("AR1");
  s.steps[1].coef = s.steps[1].coef + bigcomplex(bigfloat("3e-10"));
  s.steps[3].coef = s.steps[3].coef - bigcomplex(bigfloat("3e-10"));
  const auto coarse = write("ar1-8.txt", format_method_file("AR1-8", 5, "", "", s, 8));
  const auto fine = write("ar1-17.txt", format_method_file("AR1-17", 5, "", "", s, 17));
  EXPECT_NO_THROW(read_method_file(coarse));
  EXPECT_NE(error_of(fine).find("declares order 5"), std::string::npos) << error_of(fine);
}
