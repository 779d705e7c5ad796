#include "vrdeform/study/study_analysis.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>

#include "vrdeform/core/text_tokens.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"
#include "vrdeform/io/svg_chart.h"
#include "vrdeform/io/svg_raster.h"
#include "vrdeform/metrics/sample_stats.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// The lines of a small CSV file with their line numbers, each split at commas; the header checked
// and left out, blank lines skipped.
struct CsvRow {
  std::size_t line = 0;
  std::vector<std::string_view> fields;
};
std::vector<CsvRow> readCsv(const std::string& text, const fs::path& path,
                            const std::vector<std::string_view>& header) {
  std::vector<CsvRow> rows;
  std::size_t line = 0, start = 0;
  bool sawHeader = false;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string_view raw = trim(std::string_view(text).substr(start, end - start));
    ++line;
    start = end + 1;
    if (raw.empty()) continue;
    CsvRow row{line, {}};
    for (std::size_t from = 0;;) {
      const std::size_t comma = raw.find(',', from);
      row.fields.push_back(trim(raw.substr(from, comma == std::string_view::npos ? comma : comma - from)));
      if (comma == std::string_view::npos) break;
      from = comma + 1;
    }
    if (row.fields.size() != header.size())
      throw Error(fmt::format("{}:{}: expected {} comma-separated fields ({}), got {}", path.string(), line,
                              header.size(), fmt::join(header, ","), row.fields.size()));
    if (!sawHeader) {
      sawHeader = true;
      if (row.fields != header)
        throw Error(fmt::format("{}:{}: expected the header '{}'", path.string(), line, fmt::join(header, ",")));
      continue;
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

template <typename T, typename Name>
std::optional<std::size_t> indexOf(const std::vector<T>& items, std::string_view name, Name nameOf) {
  for (std::size_t i = 0; i < items.size(); ++i)
    if (nameOf(items[i]) == name) return i;
  return std::nullopt;
}

// The k of a participant folder's name P<k> (k >= 1), or nullopt for any other name.
std::optional<std::size_t> participantNumber(const std::string& name) {
  if (name.size() < 2 || name[0] != 'P') return std::nullopt;
  std::size_t k = 0;
  const auto [end, error] = std::from_chars(name.data() + 1, name.data() + name.size(), k);
  if (error != std::errc() || end != name.data() + name.size() || k == 0) return std::nullopt;
  return k;
}

std::optional<std::size_t> conditionIndex(const StudySpec& study, std::string_view name) {
  return indexOf(study.conditions, name, [](const StudyCondition& c) -> std::string_view { return c.name; });
}

// free_text.json into p.freeText; each entry checked against the study's items and conditions.
void readFreeText(const StudySpec& study, const fs::path& file, ParticipantAnswers& p) {
  const nlohmann::json j = nlohmann::json::parse(io::readFileBytes(file), nullptr, false);
  if (!j.is_array()) throw Error(fmt::format("{}: expected a JSON array of free-text answers", file.string()));
  for (std::size_t n = 0; n < j.size(); ++n) {
    const auto fail = [&](std::string_view what) {
      throw Error(fmt::format("{}: answer {}: {}", file.string(), n + 1, what));
    };
    const nlohmann::json& e = j[n];
    if (!e.is_object() || !e.contains("item") || !e["item"].is_string() || !e.contains("text") ||
        !e["text"].is_string())
      fail("expected an object with the strings \"item\" and \"text\"");
    FreeTextAnswer a;
    const std::string item = e["item"];
    const std::optional<std::size_t> f =
        indexOf(study.freeTexts, item, [](const StudyFreeText& x) -> std::string_view { return x.id; });
    if (!f) fail(fmt::format("no free-text item '{}' in the study", io::printable(item)));
    a.item = *f;
    if (e.contains("condition")) {
      if (!study.freeTexts[*f].perCondition) fail(fmt::format("{} is asked once, after all conditions", item));
      const std::string name = e["condition"].is_string() ? e["condition"].get<std::string>() : "";
      a.condition = conditionIndex(study, name);
      if (!a.condition) fail(fmt::format("no condition '{}' in the study", io::printable(name)));
    } else if (study.freeTexts[*f].perCondition) {
      fail(fmt::format("{} is asked after each condition: the answer needs its \"condition\"", item));
    }
    if (std::any_of(p.freeText.begin(), p.freeText.end(),
                    [&](const FreeTextAnswer& x) { return x.item == a.item && x.condition == a.condition; }))
      fail(fmt::format("a second answer to {}", item));
    a.text = e["text"];
    p.freeText.push_back(std::move(a));
  }
}

// A CSV field as RFC 4180 writes it: quoted (quotes doubled) when it holds a comma, a quote or a
// line break.
std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

ParticipantAnswers readParticipant(const StudySpec& study, const fs::path& dir, std::size_t number) {
  ParticipantAnswers p;
  p.number = number;
  p.id = dir.filename().string();
  p.answers.assign(study.conditions.size(), std::vector<std::optional<int>>(study.questions.size()));
  p.comparisons.assign(study.comparisons.size(), std::nullopt);
  if (const fs::path file = dir / "answers.csv"; fs::exists(file)) {
    const std::string text = io::readFileBytes(file);
    for (const CsvRow& row : readCsv(text, file, {"condition", "item", "answer"})) {
      const auto fail = [&](std::string_view what) {
        throw Error(fmt::format("{}:{}: {}", file.string(), row.line, what));
      };
      const std::optional<std::size_t> c = conditionIndex(study, row.fields[0]);
      if (!c) fail(fmt::format("no condition '{}' in the study", io::printable(row.fields[0])));
      const std::optional<std::size_t> q =
          indexOf(study.questions, row.fields[1], [](const StudyQuestion& x) -> std::string_view { return x.id; });
      if (!q) fail(fmt::format("no question '{}' in the study", io::printable(row.fields[1])));
      std::int64_t answer = 0;
      if (!io::parseInteger(row.fields[2], answer) || answer < 1 || answer > study.points)
        fail(fmt::format("answer '{}' is not an integer in 1..{}", io::printable(row.fields[2]), study.points));
      if (p.answers[*c][*q]) fail(fmt::format("a second answer to {} in condition {}", row.fields[1], row.fields[0]));
      p.answers[*c][*q] = int(answer);
    }
  }
  if (const fs::path file = dir / "comparisons.csv"; fs::exists(file)) {
    const std::string text = io::readFileBytes(file);
    for (const CsvRow& row : readCsv(text, file, {"item", "rating"})) {
      const auto fail = [&](std::string_view what) {
        throw Error(fmt::format("{}:{}: {}", file.string(), row.line, what));
      };
      const std::optional<std::size_t> d =
          indexOf(study.comparisons, row.fields[0], [](const StudyComparison& x) -> std::string_view { return x.id; });
      if (!d) fail(fmt::format("no comparison '{}' in the study", io::printable(row.fields[0])));
      std::int64_t rating = 0;
      if (!io::parseInteger(row.fields[1], rating) || rating < -study.comparisonRange || rating > study.comparisonRange)
        fail(fmt::format("rating '{}' is not an integer in -{}..{}", io::printable(row.fields[1]),
                         study.comparisonRange, study.comparisonRange));
      if (p.comparisons[*d]) fail(fmt::format("a second rating of {}", row.fields[0]));
      p.comparisons[*d] = int(rating);
    }
  }
  if (const fs::path file = dir / "free_text.json"; fs::exists(file)) readFreeText(study, file, p);
  return p;
}

// Participants with a value in both `a` and `b`, as two paired lists.
PairedTest pairedTest(const std::string& measure, bool dimension, std::size_t ia, std::size_t ib,
                      const std::vector<std::optional<double>>& a, const std::vector<std::optional<double>>& b) {
  std::vector<double> x, y;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k] && b[k]) {
      x.push_back(*a[k]);
      y.push_back(*b[k]);
    }
  return {measure, dimension, ia, ib, x.size(), wilcoxonSignedRank(x, y)};
}

std::string number(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : std::string("NA"); }

// A figure as SVG (for the web and further editing) and PNG (for slides and word processors).
void writeFigure(const std::filesystem::path& stem, const std::string& svg) {
  writeFile(stem.string() + ".svg", svg);
  writeSvgAsPng(svg, stem.string() + ".png");
}

}  // namespace

Description describe(std::vector<double> values) {
  Description d;
  d.n = values.size();
  if (values.empty()) {
    d.mean = d.sd = d.median = d.q1 = d.q3 = std::nan("");
    return d;
  }
  std::sort(values.begin(), values.end());
  double sum = 0;
  for (double v : values) sum += v;
  d.mean = sum / double(d.n);
  double squares = 0;
  for (double v : values) squares += (v - d.mean) * (v - d.mean);
  d.sd = d.n > 1 ? std::sqrt(squares / double(d.n - 1)) : std::nan("");
  d.median = percentileOfSorted(values, 0.5);
  d.q1 = percentileOfSorted(values, 0.25);
  d.q3 = percentileOfSorted(values, 0.75);
  return d;
}

std::vector<ParticipantAnswers> readStudyAnswers(const StudySpec& study, const fs::path& dataDir) {
  std::error_code error;
  if (!fs::is_directory(dataDir, error)) throw Error(fmt::format("{}: not a folder", dataDir.string()));
  std::vector<ParticipantAnswers> out;
  for (const fs::directory_entry& entry : fs::directory_iterator(dataDir, error))
    if (const std::optional<std::size_t> k = participantNumber(entry.path().filename().string());
        k && entry.is_directory())
      out.push_back(readParticipant(study, entry.path(), *k));
  if (error) throw Error(fmt::format("{}: cannot list: {}", dataDir.string(), error.message()));
  if (out.empty()) throw Error(fmt::format("{}: no participant folder (P1, P2, ...) in it", dataDir.string()));
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.number < b.number; });
  for (std::size_t i = 1; i < out.size(); ++i)
    if (out[i].number == out[i - 1].number)
      throw Error(fmt::format("{}: {} and {} are one participant", dataDir.string(), out[i - 1].id, out[i].id));
  return out;
}

StudyAnalysis analyseStudy(const StudySpec& study, const std::vector<ParticipantAnswers>& participants) {
  StudyAnalysis out;
  const std::size_t nc = study.conditions.size(), np = participants.size();
  for (std::size_t q = 0; q < study.questions.size(); ++q) {
    Measure m{study.questions[q].id, false, {}};
    m.byCondition.assign(nc, std::vector<std::optional<double>>(np));
    for (std::size_t c = 0; c < nc; ++c)
      for (std::size_t k = 0; k < np; ++k)
        if (const std::optional<int> a = participants[k].answers[c][q]) m.byCondition[c][k] = double(*a);
    out.measures.push_back(std::move(m));
  }
  for (const std::string& dim : study.dimensions()) {
    Measure m{dim, true, {}};
    m.byCondition.assign(nc, std::vector<std::optional<double>>(np));
    for (std::size_t c = 0; c < nc; ++c)
      for (std::size_t k = 0; k < np; ++k) {
        double sum = 0;
        int count = 0;
        for (std::size_t q = 0; q < study.questions.size(); ++q)
          if (study.questions[q].dimension == dim && participants[k].answers[c][q]) {
            sum += *participants[k].answers[c][q];
            ++count;
          }
        if (count > 0) m.byCondition[c][k] = sum / count;
      }
    out.measures.push_back(std::move(m));
  }
  for (const Measure& m : out.measures) {
    std::vector<Description> row;
    for (std::size_t c = 0; c < nc; ++c) {
      std::vector<double> values;
      for (const std::optional<double>& v : m.byCondition[c])
        if (v) values.push_back(*v);
      row.push_back(describe(std::move(values)));
    }
    out.descriptions.push_back(std::move(row));
    for (std::size_t a = 0; a < nc; ++a)
      for (std::size_t b = a + 1; b < nc; ++b)
        out.tests.push_back(pairedTest(m.name, m.dimension, a, b, m.byCondition[a], m.byCondition[b]));
    if (m.dimension) {  // by position: what each participant met first against what they met second
      std::vector<std::optional<double>> first(np), second(np);
      for (std::size_t k = 0; k < np; ++k) {
        const std::vector<std::size_t> order = study.orderOf(participants[k].number);
        first[k] = m.byCondition[order[0]][k];
        second[k] = m.byCondition[order[1]][k];
      }
      out.orderTests.push_back(pairedTest(m.name, true, 0, 1, first, second));
    }
  }
  for (std::size_t d = 0; d < study.comparisons.size(); ++d) {
    std::vector<std::optional<double>> ratings(np), zero(np, 0.0);
    std::vector<double> given;
    for (std::size_t k = 0; k < np; ++k)
      if (const std::optional<int> r = participants[k].comparisons[d]) {
        ratings[k] = double(*r);
        given.push_back(double(*r));
      }
    out.comparisons.push_back(describe(std::move(given)));
    out.comparisonTests.push_back(
        pairedTest(study.comparisons[d].id, false, study.comparisons[d].a, study.comparisons[d].b, ratings, zero));
  }
  return out;
}

void writeStudyAnalysis(const StudySpec& study, const std::vector<ParticipantAnswers>& participants,
                        const StudyAnalysis& analysis, const fs::path& outDir) {
  if (participants.empty()) throw Error("a study analysis needs at least one participant");
  prepareOutputFolder(outDir);
  const std::size_t nc = study.conditions.size();
  const auto conditionName = [&](std::size_t c) -> const std::string& { return study.conditions[c].name; };

  std::string tidy = "participant,position,condition,item,dimension,answer\n";
  for (const ParticipantAnswers& p : participants) {
    const std::vector<std::size_t> order = study.orderOf(p.number);
    for (std::size_t pos = 0; pos < order.size(); ++pos)
      for (std::size_t q = 0; q < study.questions.size(); ++q)
        if (const std::optional<int> a = p.answers[order[pos]][q])
          tidy += fmt::format("{},{},{},{},{},{}\n", p.id, pos + 1, conditionName(order[pos]), study.questions[q].id,
                              study.questions[q].dimension, *a);
  }
  writeFile(outDir / "tidy.csv", tidy);

  std::string freeText = "participant,position,condition,item,text\n";
  for (const ParticipantAnswers& p : participants) {
    const std::vector<std::size_t> order = study.orderOf(p.number);
    for (const FreeTextAnswer& a : p.freeText) {
      const std::size_t pos =
          a.condition ? std::size_t(std::find(order.begin(), order.end(), *a.condition) - order.begin()) + 1 : 0;
      freeText +=
          fmt::format("{},{},{},{},{}\n", p.id, pos ? fmt::to_string(pos) : "",
                      a.condition ? conditionName(*a.condition) : "", study.freeTexts[a.item].id, csvField(a.text));
    }
  }
  writeFile(outDir / "free_text.csv", freeText);

  std::string descriptive = "measure,kind,condition,n,mean,sd,median,q1,q3\n";
  for (std::size_t m = 0; m < analysis.measures.size(); ++m)
    for (std::size_t c = 0; c < nc; ++c) {
      const Description& d = analysis.descriptions[m][c];
      descriptive += fmt::format("{},{},{},{},{},{},{},{},{}\n", analysis.measures[m].name,
                                 analysis.measures[m].dimension ? "dimension" : "item", conditionName(c), d.n,
                                 number(d.mean), number(d.sd), number(d.median), number(d.q1), number(d.q3));
    }
  writeFile(outDir / "descriptive.csv", descriptive);

  const auto testRow = [&](const PairedTest& t, const std::string& a, const std::string& b) {
    const WilcoxonResult& r = t.result;
    return fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", t.measure, t.dimension ? "dimension" : "item", a, b,
                       t.pairs, r.n, number(r.wPlus), number(r.wMinus), number(r.z), number(r.p),
                       r.exact ? "exact" : "normal", number(r.effectSize));
  };
  const std::string testHeader = "measure,kind,a,b,pairs,nonzero,w_plus,w_minus,z,p,method,r\n";
  std::string tests = testHeader;
  for (const PairedTest& t : analysis.tests) tests += testRow(t, conditionName(t.a), conditionName(t.b));
  writeFile(outDir / "tests.csv", tests);
  std::string order = testHeader;
  for (const PairedTest& t : analysis.orderTests) order += testRow(t, "first", "second");
  writeFile(outDir / "order.csv", order);

  std::string comparisons = "item,a,b,n,mean,sd,median,q1,q3,w_plus,w_minus,z,p,method,r\n";
  for (std::size_t d = 0; d < study.comparisons.size(); ++d) {
    const Description& x = analysis.comparisons[d];
    const WilcoxonResult& r = analysis.comparisonTests[d].result;
    comparisons +=
        fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", study.comparisons[d].id,
                    conditionName(study.comparisons[d].a), conditionName(study.comparisons[d].b), x.n, number(x.mean),
                    number(x.sd), number(x.median), number(x.q1), number(x.q3), number(r.wPlus), number(r.wMinus),
                    number(r.z), number(r.p), r.exact ? "exact" : "normal", number(r.effectSize));
  }
  writeFile(outDir / "comparisons.csv", comparisons);

  // The paper's figures: the dimensions' box plots per condition, the comparisons' ratings, and each
  // item's mean difference between the conditions of every pair.
  BoxPlot dims{study.name + ": dimensions", fmt::format("rating (1-{})", study.points), {}, {}, {},
               {1.0, double(study.points)}};
  for (std::size_t c = 0; c < nc; ++c) dims.series.push_back(conditionName(c));
  for (const Measure& m : analysis.measures)
    if (m.dimension) {
      dims.groups.push_back(m.name);
      auto& groupValues = dims.values.emplace_back();
      for (std::size_t c = 0; c < nc; ++c) {
        auto& box = groupValues.emplace_back();
        for (const std::optional<double>& v : m.byCondition[c])
          if (v) box.push_back(*v);
      }
    }
  writeFigure(outDir / "dimensions", svgBoxPlot(dims));
  if (!study.comparisons.empty()) {
    BoxPlot ratings{study.name + ": direct comparisons (negative favours the first condition)",
                    "rating",
                    {"rating"},
                    {},
                    {},
                    {-double(study.comparisonRange), double(study.comparisonRange)}};
    for (std::size_t d = 0; d < study.comparisons.size(); ++d) {
      ratings.groups.push_back(study.comparisons[d].id);
      std::vector<double> box;
      for (const ParticipantAnswers& p : participants)
        if (p.comparisons[d]) box.push_back(*p.comparisons[d]);
      ratings.values.push_back({box});
    }
    writeFigure(outDir / "comparisons", svgBoxPlot(ratings));
  }
  Heatmap heat{study.name + ": mean difference per item", {}, {}, {}, 1.0};
  for (std::size_t a = 0; a < nc; ++a)
    for (std::size_t b = a + 1; b < nc; ++b) heat.columns.push_back(conditionName(a) + " - " + conditionName(b));
  for (const Measure& m : analysis.measures) {
    if (m.dimension) continue;
    heat.rows.push_back(m.name);
    auto& row = heat.values.emplace_back();
    for (std::size_t a = 0; a < nc; ++a)
      for (std::size_t b = a + 1; b < nc; ++b) {
        double sum = 0;
        int n = 0;
        for (std::size_t k = 0; k < participants.size(); ++k)
          if (m.byCondition[a][k] && m.byCondition[b][k]) {
            sum += *m.byCondition[a][k] - *m.byCondition[b][k];
            ++n;
          }
        row.push_back(n > 0 ? sum / n : std::nan(""));
        if (n > 0) heat.range = std::max(heat.range, std::ceil(std::abs(sum / n)));
      }
  }
  writeFigure(outDir / "items", svgHeatmap(heat));

  // The report: the dimensions first (the paper's figures), then every item, the order, the comparisons.
  std::vector<std::string_view> names;
  for (const StudyCondition& c : study.conditions) names.push_back(c.name);
  std::string md = fmt::format("# {}\n\n{}{} participants ({} to {}), {} conditions ({}).\n\n", study.name,
                               study.description.empty() ? "" : study.description + "\n\n", participants.size(),
                               participants.front().id, participants.back().id, nc, fmt::join(names, ", "));
  const auto table = [&](bool dimensions) {
    std::string t = "| measure | condition | n | mean | SD | median | IQR |\n|---|---|---:|---:|---:|---:|---|\n";
    for (std::size_t m = 0; m < analysis.measures.size(); ++m)
      if (analysis.measures[m].dimension == dimensions)
        for (std::size_t c = 0; c < nc; ++c) {
          const Description& d = analysis.descriptions[m][c];
          t += fmt::format("| {} | {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f}-{:.2f} |\n", analysis.measures[m].name,
                           conditionName(c), d.n, d.mean, d.sd, d.median, d.q1, d.q3);
        }
    t += "\n| measure | conditions | pairs | W+ | W- | z | p | r |\n|---|---|---:|---:|---:|---:|---:|---:|\n";
    for (const PairedTest& x : analysis.tests)
      if (x.dimension == dimensions)
        t += fmt::format("| {} | {} vs {} | {} | {} | {} | {:.3f} | {:.4f}{} | {:.2f} |\n", x.measure,
                         conditionName(x.a), conditionName(x.b), x.pairs, x.result.wPlus, x.result.wMinus, x.result.z,
                         x.result.p, x.result.exact ? " (exact)" : "", x.result.effectSize);
    return t;
  };
  md +=
      "## Dimensions\n\nEach participant's mean over a dimension's items, per condition; Wilcoxon signed-rank "
      "tests on the pairs (exact p for up to 50 untied pairs), effect size r = |z| / sqrt(n).\n\n" +
      table(true) + "\n## Items\n\n" + table(false);
  md +=
      "\n## Order\n\nPer dimension, the condition each participant met first against the one met second.\n\n"
      "| dimension | pairs | z | p |\n|---|---:|---:|---:|\n";
  for (const PairedTest& t : analysis.orderTests)
    md += fmt::format("| {} | {} | {:.3f} | {:.4f} |\n", t.measure, t.pairs, t.result.z, t.result.p);
  if (!study.comparisons.empty()) {
    md += fmt::format(
        "\n## Direct comparisons\n\nRated on -{0}..{0}: negative favours the first condition, 0 no "
        "difference, positive the second; Wilcoxon signed-rank against 0.\n\n![comparisons](comparisons.svg)\n\n"
        "| item | question | conditions | n | mean | median | IQR | p |\n|---|---|---|---:|---:|---:|---|---:|\n",
        study.comparisonRange);
    for (std::size_t d = 0; d < study.comparisons.size(); ++d) {
      const Description& x = analysis.comparisons[d];
      md += fmt::format("| {} | {} | {} vs {} | {} | {:.2f} | {:.2f} | {:.2f}-{:.2f} | {:.4f} |\n",
                        study.comparisons[d].id, study.comparisons[d].text, conditionName(study.comparisons[d].a),
                        conditionName(study.comparisons[d].b), x.n, x.mean, x.median, x.q1, x.q3,
                        analysis.comparisonTests[d].result.p);
    }
  }
  if (!study.freeTexts.empty()) {
    md += "\n## Free text\n";
    for (std::size_t f = 0; f < study.freeTexts.size(); ++f) {
      md += fmt::format("\n### {}: {}\n\n", study.freeTexts[f].id, study.freeTexts[f].text);
      for (const ParticipantAnswers& p : participants)
        for (const FreeTextAnswer& a : p.freeText) {
          if (a.item != f) continue;
          std::string text = a.text;
          std::replace_if(
              text.begin(), text.end(), [](char ch) { return ch == '\n' || ch == '\r'; }, ' ');
          md += fmt::format("- {}{}: {}\n", p.id, a.condition ? fmt::format(" ({})", conditionName(*a.condition)) : "",
                            text);
        }
    }
  }
  md +=
      "\nFiles: tidy.csv (one row per answer), descriptive.csv, tests.csv, order.csv, comparisons.csv, "
      "free_text.csv; the "
      "figures dimensions, items and comparisons, each as .svg and .png.\n";
  writeFile(outDir / "report.md", md);
}

}  // namespace vrd
