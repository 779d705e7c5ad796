#include "mesh_commands.h"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <memory>

#include "vrdeform/error.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/io/tet_io.h"
#include "vrdeform/io/tetrahedralise.h"
#include "vrdeform/mesh/boundary.h"
#include "vrdeform/mesh/surface_check.h"
#include "vrdeform/mesh/tet_quality.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

struct CheckArgs {
  std::string input;
  bool open = false;
  bool noIntersections = false;
};

int check(const CheckArgs& a) {
  const TriMesh surface = readSurface(a.input);
  const SurfaceReport report =
      checkSurface(surface, {.requireClosed = !a.open, .checkSelfIntersection = !a.noIntersections});
  fmt::print("{}: {}\n", a.input, report.summary());
  return report.ok() ? 0 : 1;
}

struct TetArgs {
  std::string input, output, surfaceOutput;
  std::string mesher = "builtin";
  std::size_t tets = 0;
  double maxVolume = 0, quality = 1.5, timeout = 300;
  std::string tetgen = "tetgen";
  bool rawVolume = false;
};

int tetrahedraliseCommand(const TetArgs& a) {
  if (!a.output.empty()) checkTetMeshOutput(a.output);
  if (!a.surfaceOutput.empty()) checkSurfaceOutput(a.surfaceOutput);
  const TriMesh surface = readSurface(a.input);
  TetrahedraliseOptions options;
  options.mesher = a.mesher == "tetgen" ? Mesher::TetGen : Mesher::Builtin;
  options.targetTets = a.tets;
  options.maxVolume = a.maxVolume;
  options.radiusEdge = a.quality;
  options.preserveVolume = !a.rawVolume;
  options.tetgenProgram = a.tetgen;
  options.timeoutSeconds = a.timeout;
  const auto start = std::chrono::steady_clock::now();
  const Tetrahedralisation result = tetrahedralise(surface, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("{}: {} tets from {} ({} run{}, {:.2f} s, volume bound {:.4g}{})\n", a.input, result.mesh.tets.size(),
             toString(options.mesher), result.runs, result.runs == 1 ? "" : "s", seconds, result.maxVolume,
             options.mesher == Mesher::TetGen ? fmt::format(", radius-edge bound {}", result.radiusEdge) : "");
  if (a.tets > 0 && std::abs(double(result.mesh.tets.size()) - double(a.tets)) > options.countTolerance * a.tets)
    fmt::print("note: {} tets is as close to {} as this mesher gets on this surface\n", result.mesh.tets.size(),
               a.tets);
  if (const std::string dropped = droppedMessage(result); !dropped.empty()) fmt::print("note: {}\n", dropped);
  fmt::print("{}", measureTetQuality(result.mesh, &surface).table());
  if (!a.output.empty()) {
    writeTetMesh(a.output, result.mesh);
    fmt::print("wrote {}\n", a.output);
  }
  if (!a.surfaceOutput.empty()) {
    writeSurface(a.surfaceOutput, boundarySurface(result.mesh));
    fmt::print("wrote {}\n", a.surfaceOutput);
  }
  return 0;
}

struct QualityArgs {
  std::string input, surface;
};

int quality(const QualityArgs& a) {
  const TetMesh mesh = readTetMesh(a.input);
  std::optional<TriMesh> surface;
  if (!a.surface.empty()) surface = readSurface(a.surface);
  const TetQuality q = measureTetQuality(mesh, surface ? &*surface : nullptr);
  fmt::print("{}\n{}", a.input, q.table());
  return q.inverted == 0 && q.degenerate == 0 && q.invalid == 0 ? 0 : 1;
}

struct ConvertArgs {
  std::string input, output;
  bool ascii = false;
};

int convert(const ConvertArgs& a) {
  const bool surfaceOut = isSurfaceFile(a.output);
  if (isSurfaceFile(a.input)) {
    if (!surfaceOut) throw Error(fmt::format("{}: a surface becomes a tet mesh with `vrdeform mesh tet`", a.output));
    writeSurface(a.output, readSurface(a.input), {.binary = !a.ascii});
  } else {
    const TetMesh mesh = readTetMesh(a.input);
    if (surfaceOut)
      writeSurface(a.output, boundarySurface(mesh), {.binary = !a.ascii});
    else
      writeTetMesh(a.output, mesh, {.vtuEncoding = a.ascii ? VtuEncoding::Ascii : VtuEncoding::AppendedRaw});
  }
  fmt::print("wrote {}\n", a.output);
  return 0;
}

// `vrdeform mesh IN OUT`: whatever turns IN into OUT. A surface is checked, then tetrahedralised
// (a tet format out) or converted; a tet mesh is measured, then converted. Any failure is one line
// and exit 1.
struct AutoArgs {
  std::string input, output, mesher = "builtin";
  std::size_t tets = 0;
};

int meshInOut(const AutoArgs& a) {
  if (a.input.empty() || a.output.empty())
    throw Error("mesh: give IN and OUT, or a command (check, tet, quality, convert, compare); see --help");
  try {
    if (isSurfaceFile(a.input) && !isSurfaceFile(a.output)) {
      TetArgs tet;
      tet.input = a.input, tet.output = a.output, tet.mesher = a.mesher, tet.tets = a.tets;
      if (check({a.input}) != 0) throw Error(fmt::format("{}: not a closed, clean surface (see above)", a.input));
      return tetrahedraliseCommand(tet);
    }
    if (isSurfaceFile(a.input)) {
      if (check({a.input, true}) != 0) throw Error(fmt::format("{}: the surface has defects (see above)", a.input));
    } else if (quality({a.input, ""}) != 0) {
      throw Error(fmt::format("{}: the tet mesh has inverted, degenerate or invalid tets (see above)", a.input));
    }
    return convert({a.input, a.output});
  } catch (const Error& e) {
    fmt::print(stderr, "vrdeform: {}\n", e.what());
    return 1;
  }
}

struct CompareArgs {
  std::vector<std::string> inputs;
  std::vector<std::size_t> tets{1500};
  std::string tetgen = "tetgen";
};

// Both meshers side by side on each surface and target: a Markdown table.
int compare(const CompareArgs& a) {
  fmt::print(
      "| surface | mesher | target | tets | runs | time (s) | dihedral min-max (deg) | radius-edge max | volume error "
      "|\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  int failures = 0;
  for (const std::string& input : a.inputs) {
    const TriMesh surface = readSurface(input);
    for (std::size_t target : a.tets)
      for (Mesher mesher : {Mesher::Builtin, Mesher::TetGen}) {
        TetrahedraliseOptions options{.mesher = mesher, .targetTets = target};
        options.tetgenProgram = a.tetgen;
        const auto start = std::chrono::steady_clock::now();
        try {
          const Tetrahedralisation r = tetrahedralise(surface, options);
          const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          const TetQuality q = measureTetQuality(r.mesh, &surface);
          fmt::print("| {} | {} | {} | {} | {} | {:.2f} | {:.1f}-{:.1f} | {:.2f} | {:+.3f}% |\n",
                     fs::path(input).filename().string(), toString(mesher), target, r.mesh.tets.size(), r.runs, s,
                     q.minDihedralDeg, q.maxDihedralDeg, q.maxRadiusEdge, 100 * q.volumeError.value_or(0));
        } catch (const Error& e) {
          ++failures;
          fmt::print("| {} | {} | {} | failed: {} |||||\n", fs::path(input).filename().string(), toString(mesher),
                     target, e.what());
        }
      }
  }
  return failures == 0 ? 0 : 1;
}

}  // namespace

std::function<int()> addMeshCommands(CLI::App& app) {
  CLI::App* mesh = app.add_subcommand("mesh", "Check, tetrahedralise, measure and convert meshes");
  mesh->require_subcommand(0, 1);
  auto autoArgs = std::make_shared<AutoArgs>();
  mesh->add_option("in", autoArgs->input, "Without a command: the mesh to read (surface or tet mesh)");
  mesh->add_option("out", autoArgs->output,
                   "Without a command: the mesh to write; a tet format from a surface tetrahedralises it");
  mesh->add_option("--tets", autoArgs->tets, "IN OUT: target tet count")->check(CLI::Range(1, 100'000'000));
  mesh->add_option("--mesher", autoArgs->mesher, "IN OUT: builtin or tetgen")
      ->check(CLI::IsMember({"builtin", "tetgen"}))
      ->capture_default_str();

  auto checkArgs = std::make_shared<CheckArgs>();
  CLI::App* checkCmd =
      mesh->add_subcommand("check", "Check a surface: closed, manifold, oriented, no self-intersections");
  checkCmd->add_option("surface", checkArgs->input, "Surface file (.obj, .off, .stl, .ply)")->required();
  checkCmd->add_flag("--open", checkArgs->open, "Allow an open surface (cloth)");
  checkCmd->add_flag("--no-intersections", checkArgs->noIntersections, "Skip the self-intersection test");

  auto tetArgs = std::make_shared<TetArgs>();
  CLI::App* tetCmd = mesh->add_subcommand("tet", "Tetrahedralise a closed surface");
  tetCmd->add_option("surface", tetArgs->input, "Surface file (.obj, .off, .stl, .ply)")->required();
  tetCmd->add_option("-o,--output", tetArgs->output, "Tet mesh to write (.node, .vtu, .vtk, .mesh, .msh)");
  tetCmd->add_option("--surface-out", tetArgs->surfaceOutput, "Also write the tet mesh's boundary surface");
  tetCmd->add_option("--mesher", tetArgs->mesher, "builtin (isosurface stuffing) or tetgen (runs the tetgen program)")
      ->check(CLI::IsMember({"builtin", "tetgen"}))
      ->capture_default_str();
  tetCmd->add_option("--tets", tetArgs->tets, "Target tet count (within 15%)")->check(CLI::Range(1, 100'000'000));
  tetCmd->add_option("--max-volume", tetArgs->maxVolume, "Largest tet volume, in the surface's units cubed")
      ->check(CLI::PositiveNumber);
  tetCmd->add_option("--quality", tetArgs->quality, "TetGen: radius-edge bound (0 for none)")->capture_default_str();
  tetCmd->add_option("--tetgen", tetArgs->tetgen, "The tetgen program")->capture_default_str();
  tetCmd->add_option("--timeout", tetArgs->timeout, "Seconds before a TetGen run is killed")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  tetCmd->add_flag("--raw-volume", tetArgs->rawVolume,
                   "Built-in: leave boundary vertices on the surface (no volume fix)");

  auto qualityArgs = std::make_shared<QualityArgs>();
  CLI::App* qualityCmd = mesh->add_subcommand("quality", "Quality report of a tet mesh");
  qualityCmd->add_option("tets", qualityArgs->input, "Tet mesh (.node, .ele, .vtu, .vtk, .mesh, .msh)")->required();
  qualityCmd->add_option("--surface", qualityArgs->surface, "Compare the enclosed volume with this surface");

  auto convertArgs = std::make_shared<ConvertArgs>();
  CLI::App* convertCmd =
      mesh->add_subcommand("convert", "Convert between formats (a tet mesh to a surface gives its boundary)");
  convertCmd->add_option("input", convertArgs->input, "Surface or tet mesh")->required();
  convertCmd->add_option("output", convertArgs->output, "Output; the format follows the extension")->required();
  convertCmd->add_flag("--ascii", convertArgs->ascii, "Text instead of binary (.stl, .ply, .vtu)");

  auto compareArgs = std::make_shared<CompareArgs>();
  CLI::App* compareCmd = mesh->add_subcommand("compare", "Both meshers side by side (a Markdown table)");
  compareCmd->add_option("surfaces", compareArgs->inputs, "Closed surfaces")->required();
  compareCmd->add_option("--tets", compareArgs->tets, "Target tet counts")->capture_default_str();
  compareCmd->add_option("--tetgen", compareArgs->tetgen, "The tetgen program")->capture_default_str();

  return [=]() -> int {
    if (*checkCmd) return check(*checkArgs);
    if (*tetCmd) return tetrahedraliseCommand(*tetArgs);
    if (*qualityCmd) return quality(*qualityArgs);
    if (*convertCmd) return convert(*convertArgs);
    if (*compareCmd) return compare(*compareArgs);
    return meshInOut(*autoArgs);
  };
}

}  // namespace vrd
