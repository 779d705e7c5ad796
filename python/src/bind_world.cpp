// The solver from Python: settings, materials, colliders and World.

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>

#include "bindings.h"
#include "views.h"
#include "vrdeform/error.h"
#include "vrdeform/mesh/tet_mesh.h"
#include "vrdeform/sim/body_model.h"
#include "vrdeform/sim/world.h"

namespace py = pybind11;

namespace vrd::python {
namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

Quat quaternion(const std::array<float, 4>& wxyz) {
  const Quat q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  if (!(std::isfinite(q.norm()) && q.norm() > 0.0f))
    throw Error("rotation: a quaternion (w, x, y, z) of non-zero, finite length");
  return q.normalized();
}

const Body& bodyOf(const World& world, BodyId id) {
  if (id >= world.bodyCount())
    throw Error(fmt::format("body {} does not exist: the world has {} bodies", id, world.bodyCount()));
  return world.body(id);
}

// A body's particles as an (n, 3) array to write: checked for shape and finite values.
FloatArray particleRows(const World& world, BodyId id, const FloatArray& values, const char* what) {
  const Body& b = bodyOf(world, id);
  if (values.ndim() != 2 || values.shape(1) != 3 || values.shape(0) != py::ssize_t(b.particleCount))
    throw Error(fmt::format("{}: an array of shape ({}, 3) for body {}", what, b.particleCount, id));
  for (py::ssize_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values.data()[i])) throw Error(fmt::format("{}: values must be finite", what));
  return values;
}

py::dict stageDict(const std::array<double, kStageCount>& values) {
  py::dict d;
  for (std::size_t s = 0; s < kStageCount; ++s) d[py::str(std::string(stageName(Stage(s))))] = values[s];
  return d;
}

}  // namespace

void bindWorld(py::module_& m) {
  py::enum_<SimdLevel>(m, "SimdLevel", "How many constraints of one colour the solver projects at once")
      .value("OFF", SimdLevel::Off)
      .value("SSE", SimdLevel::Sse)
      .value("AVX2", SimdLevel::Avx2)
      .value("AVX512", SimdLevel::Avx512)
      .value("BEST", SimdLevel::Best);
  py::enum_<NanPolicy>(m, "NanPolicy", "What happens to a body in which a NaN appears")
      .value("FREEZE", NanPolicy::Freeze)
      .value("RESET", NanPolicy::Reset);
  py::enum_<FingertipContactMode>(m, "FingertipContactMode", "What a fingertip's sphere touches")
      .value("PARTICLES", FingertipContactMode::Particles)
      .value("TRIANGLES", FingertipContactMode::Triangles);

  py::class_<SolverSettings>(m, "SolverSettings", "Settings of the XPBD solver (Algorithm 1); see docs/scenes.md")
      .def(py::init<>())
      .def_readwrite("time_step", &SolverSettings::timeStep, "dt of one step (s)")
      .def_readwrite("substeps", &SolverSettings::substeps)
      .def_readwrite("iterations", &SolverSettings::iterations,
                     "Gauss-Seidel iterations per substep (the cap with a tolerance)")
      .def_readwrite("gravity", &SolverSettings::gravity)
      .def_readwrite("linear_damping", &SolverSettings::linearDamping, "c (1/s): v *= 1 - c h each substep")
      .def_readwrite("on_nan", &SolverSettings::onNan)
      .def_readwrite("time_stages", &SolverSettings::timeStages)
      .def_readwrite("simd", &SolverSettings::simd)
      .def_readwrite("threads", &SolverSettings::threads, "solver threads; 0: automatic")
      .def_readwrite("threads_fall_back", &SolverSettings::threadsFallBack)
      .def_readwrite("fuse_strain_volume", &SolverSettings::fuseStrainVolume)
      .def_readwrite("measure_residuals", &SolverSettings::measureResiduals)
      .def_readwrite("tolerance", &SolverSettings::tolerance,
                     "adaptive iterations: > 0 iterates until corrections fall below it")
      .def_readwrite("warm_start", &SolverSettings::warmStart)
      .def_property_readonly("substep_size", &SolverSettings::substepSize);

  py::class_<ConstraintMaterial>(m, "ConstraintMaterial", "Compliance alpha and damping beta of one constraint type")
      .def(py::init([](float compliance, float damping) {
             return ConstraintMaterial{compliance, damping};
           }),
           py::arg("compliance") = 0.3f, py::arg("damping") = 0.03f)
      .def_readwrite("compliance", &ConstraintMaterial::compliance)
      .def_readwrite("damping", &ConstraintMaterial::damping);
  py::class_<ElasticModuli>(m, "ElasticModuli",
                            "Young's modulus (Pa), Poisson's ratio, density (kg/m^3), Rayleigh damping (s)")
      .def(py::init([](float youngs, float poisson, float density, float rayleigh) {
             return ElasticModuli{youngs, poisson, density, rayleigh};
           }),
           py::arg("youngs"), py::arg("poisson"), py::arg("density"), py::arg("rayleigh_damping") = 0.0f)
      .def_readwrite("youngs", &ElasticModuli::youngsModulus)
      .def_readwrite("poisson", &ElasticModuli::poissonRatio)
      .def_readwrite("density", &ElasticModuli::density)
      .def_readwrite("rayleigh_damping", &ElasticModuli::rayleighDamping);
  py::class_<Material>(m, "Material", "A body's material: elastic moduli, or compliances per constraint type")
      .def(py::init<>())
      .def(py::init([](const ElasticModuli& e) {
             Material mat;
             mat.elastic = e;
             return mat;
           }),
           py::arg("elastic"))
      .def_readwrite("density", &Material::density)
      .def_readwrite("areal_density", &Material::arealDensity)
      .def_readwrite("particle_mass", &Material::particleMass)
      .def_readwrite("distance", &Material::distance)
      .def_readwrite("volume", &Material::volume)
      .def_readwrite("strain_stretch", &Material::strainStretch)
      .def_readwrite("strain_shear", &Material::strainShear)
      .def_readwrite("shape_matching", &Material::shapeMatching)
      .def_readwrite("bending", &Material::bending)
      .def_readwrite("elastic", &Material::elastic)
      .def_readwrite("particle_radius", &Material::particleRadius);
  py::class_<ConstraintSet>(m, "ConstraintSet", "Which constraints a soft body gets")
      .def(py::init([](bool edges, bool volume, bool strain, bool shapeMatching) {
             return ConstraintSet{edges, volume, strain, shapeMatching};
           }),
           py::arg("edges") = false, py::arg("volume") = true, py::arg("strain") = true,
           py::arg("shape_matching") = true)
      .def_readwrite("edges", &ConstraintSet::edges)
      .def_readwrite("volume", &ConstraintSet::volume)
      .def_readwrite("strain", &ConstraintSet::strain)
      .def_readwrite("shape_matching", &ConstraintSet::shapeMatching);

  py::class_<Collider>(m, "Collider", "A static plane, sphere or box with Coulomb friction")
      .def_static("plane", &Collider::plane, py::arg("normal") = Vec3(Vec3::UnitY()),
                  py::arg("point") = Vec3(Vec3::Zero()))
      .def_static("sphere", &Collider::sphere, py::arg("center"), py::arg("radius"))
      .def_static("box", &Collider::box, py::arg("center"), py::arg("half_extents"),
                  py::arg("rotation") = Mat3(Mat3::Identity()))
      .def_readwrite("static_friction", &Collider::staticFriction)
      .def_readwrite("dynamic_friction", &Collider::dynamicFriction)
      .def_readwrite("compliance", &Collider::compliance);

  py::class_<BodyContactSettings>(m, "BodyContactSettings", "How a body touches other bodies and itself")
      .def(py::init([](bool bodies, bool self, float thickness, float staticFriction, float dynamicFriction,
                       float compliance) {
             return BodyContactSettings{bodies, self, thickness, staticFriction, dynamicFriction, compliance};
           }),
           py::arg("bodies") = true, py::arg("self") = false, py::arg("thickness") = 0.001f,
           py::arg("static_friction") = 0.5f, py::arg("dynamic_friction") = 0.4f, py::arg("compliance") = 0.0f)
      .def_readwrite("bodies", &BodyContactSettings::bodies)
      .def_readwrite("self", &BodyContactSettings::self)
      .def_readwrite("thickness", &BodyContactSettings::thickness)
      .def_readwrite("static_friction", &BodyContactSettings::staticFriction)
      .def_readwrite("dynamic_friction", &BodyContactSettings::dynamicFriction)
      .def_readwrite("compliance", &BodyContactSettings::compliance);

  py::class_<StepReport>(m, "StepReport", "What the last step did")
      .def_readonly("step", &StepReport::step)
      .def_readonly("iterations", &StepReport::iterations)
      .def_readonly("cold_substeps", &StepReport::coldSubsteps)
      .def_readonly("collider_contacts", &StepReport::colliderContacts)
      .def_readonly("fingertip_contacts", &StepReport::fingertipContacts)
      .def_readonly("body_contacts", &StepReport::bodyContacts)
      .def_readonly("deepest_penetration", &StepReport::deepestPenetration)
      .def_property_readonly(
          "times_ms", [](const StepReport& r) { return stageDict(r.times.ms); },
          "milliseconds per stage, summed over the substeps")
      .def_property_readonly(
          "residuals",
          [](const StepReport& r) {
            py::dict d;
            for (std::size_t s = 0; s < kStageCount; ++s)
              if (std::isfinite(r.residuals[s].max))
                d[py::str(std::string(stageName(Stage(s))))] = py::make_tuple(r.residuals[s].rms, r.residuals[s].max);
            return d;
          },
          "per constraint stage (rms, max) of the last iteration's corrections / mean rest edge, when measured");

  py::class_<World>(m, "World", R"(A simulation world: bodies, colliders, fingertips and attachments, stepped with XPBD.

Array views (positions, velocities, multipliers) show the live state without copying: they are
read-only, change with every step, and keep the world alive. While any exists the world refuses
to add bodies; write through set_positions and set_velocities.)")
      .def(py::init<const SolverSettings&>(), py::arg("settings") = SolverSettings{})
      .def_property(
          "settings", [](const World& w) { return w.settings(); }, &World::setSettings,
          "A copy of the solver settings; assign a changed copy back (validated, from the next step)")
      .def(
          "add_soft_body",
          [](World& w, const TetMesh& mesh, const Material& material, const ConstraintSet& constraints,
             const Vec3& translation, const std::array<float, 4>& rotation) {
            requireNoViews(w, "add_soft_body");
            return w.addBody(makeSoftBody(mesh, material, constraints), translation, quaternion(rotation));
          },
          py::arg("mesh"), py::arg("material") = Material{}, py::arg("constraints") = ConstraintSet{},
          py::arg("translation") = Vec3(Vec3::Zero()), py::arg("rotation") = std::array<float, 4>{1, 0, 0, 0},
          "Adds a soft body made from a tet mesh; returns its id")
      .def(
          "add_cloth",
          [](World& w, const TriMesh& mesh, const Material& material, const Vec3& translation,
             const std::array<float, 4>& rotation) {
            requireNoViews(w, "add_cloth");
            return w.addBody(makeCloth(mesh, material), translation, quaternion(rotation));
          },
          py::arg("mesh"), py::arg("material") = Material{}, py::arg("translation") = Vec3(Vec3::Zero()),
          py::arg("rotation") = std::array<float, 4>{1, 0, 0, 0}, "Adds a cloth made from a triangle mesh")
      .def_property_readonly("body_count", &World::bodyCount)
      .def(
          "particle_count", [](const World& w, BodyId id) { return bodyOf(w, id).particleCount; }, py::arg("body"))
      .def(
          "tet_count", [](const World& w, BodyId id) { return bodyOf(w, id).model->tets.size(); }, py::arg("body"))
      .def("reset_body", &World::resetBody, py::arg("body"), "Back to the initial pose, at rest")
      .def("step", &World::step, py::call_guard<py::gil_scoped_release>(),
           "Advances one time step (the GIL is released meanwhile)")
      .def(
          "steps",
          [](World& w, std::uint64_t n) {
            const auto interrupted = ctrlC();
            for (std::uint64_t k = 0; k < n; ++k) {
              w.step();
              if (interrupted()) {
                py::gil_scoped_acquire gil;
                throw py::error_already_set();  // the KeyboardInterrupt
              }
            }
          },
          py::arg("n"), py::call_guard<py::gil_scoped_release>(),
          "n steps in one call, without returning to Python between them (Ctrl-C stops it)")
      .def_property_readonly("last_step", &World::lastStep)
      .def_property_readonly("step_count", &World::stepCount)
      .def(
          "positions",
          [](py::object self, BodyId id) {
            const World& w = self.cast<const World&>();
            const Body& b = bodyOf(w, id);
            return floatView(w, self, w.particles().x[b.firstParticle].pos.data(), {b.particleCount, 3},
                             {sizeof(Point), sizeof(float)});
          },
          py::arg("body"), "Read-only (n, 3) view of the body's world positions (m)")
      .def(
          "velocities",
          [](py::object self, BodyId id) {
            const World& w = self.cast<const World&>();
            const Body& b = bodyOf(w, id);
            return floatView(w, self, w.particles().v[b.firstParticle].data(), {b.particleCount, 3},
                             {sizeof(Vec3), sizeof(float)});
          },
          py::arg("body"), "Read-only (n, 3) view of the body's velocities (m/s)")
      .def(
          "set_positions",
          [](World& w, BodyId id, const FloatArray& values) {
            const FloatArray rows = particleRows(w, id, values, "set_positions");
            const Body& b = w.body(id);
            for (Index i = 0; i < b.particleCount; ++i)
              w.particles().x[b.firstParticle + i].pos = Vec3(rows.at(i, 0), rows.at(i, 1), rows.at(i, 2));
          },
          py::arg("body"), py::arg("positions"), "Moves the body's particles (an (n, 3) array, m) before the next step")
      .def(
          "set_velocities",
          [](World& w, BodyId id, const FloatArray& values) {
            const FloatArray rows = particleRows(w, id, values, "set_velocities");
            const Body& b = w.body(id);
            for (Index i = 0; i < b.particleCount; ++i)
              w.particles().v[b.firstParticle + i] = Vec3(rows.at(i, 0), rows.at(i, 1), rows.at(i, 2));
          },
          py::arg("body"), py::arg("velocities"), "Sets the body's velocities (an (n, 3) array, m/s)")
      .def(
          "multipliers",
          [](py::object self, BodyId id) {
            const World& w = self.cast<const World&>();
            const Body& b = bodyOf(w, id);
            const auto row = [&](const std::vector<float>& l) {
              return floatView(w, self, l.data(), {py::ssize_t(l.size())}, {sizeof(float)});
            };
            py::dict d;
            d["distance"] = row(b.distanceLambda);
            d["volume"] = row(b.volumeLambda);
            d["bend"] = row(b.bendLambda);
            const py::ssize_t tets = py::ssize_t(b.strainLambda.size());
            d["strain"] = floatView(w, self, b.strainLambda.values().data(), {kStrainComponents, tets},
                                    {tets * py::ssize_t(sizeof(float)), sizeof(float)});
            d["shape_matching"] =
                floatView(w, self, b.shapeMatchLambda.empty() ? nullptr : b.shapeMatchLambda[0].data(),
                          {py::ssize_t(b.shapeMatchLambda.size()), 3}, {sizeof(Vec3), sizeof(float)});
            return d;
          },
          py::arg("body"),
          "Read-only views of the body's multipliers of the last substep, one per constraint (lambda / h^2 is the "
          "generalised force); strain is (6, tets): components 00, 11, 22, 01, 02, 12")
      .def(
          "constraint_forces",
          [](const World& w, BodyId id) {
            bodyOf(w, id);
            const std::vector<Vec3> f = w.particleConstraintForces(id);
            py::array_t<float> out({py::ssize_t(f.size()), py::ssize_t(3)});
            for (std::size_t i = 0; i < f.size(); ++i)
              for (int k = 0; k < 3; ++k) out.mutable_at(py::ssize_t(i), k) = f[i][k];
            return out;
          },
          py::arg("body"), "Net constraint force on each particle in the last substep (N), contacts included: a copy")
      .def(
          "volume",
          [](const World& w, BodyId id) {
            bodyOf(w, id);
            return w.volume(id);
          },
          py::arg("body"), "Sum of the body's signed tet volumes (m^3)")
      .def(
          "volume_loss",
          [](const World& w, BodyId id) {
            bodyOf(w, id);
            return w.volumeLoss(id);
          },
          py::arg("body"), "(v0 - v) / v0")
      .def("add_collider", &World::addCollider, py::arg("collider"))
      .def("add_fingertip", &World::addFingertip, py::arg("center"), py::arg("radius"), py::arg("compliance") = 0.0f,
           py::arg("mode") = FingertipContactMode::Particles, "A kinematic contact sphere; returns its id")
      .def("move_fingertip", &World::moveFingertip, py::arg("fingertip"), py::arg("goal"),
           "Moves the fingertip's centre to goal over the next step")
      .def(
          "set_fingertip_friction",
          [](World& w, FingertipId id, float staticFriction, float dynamicFriction) {
            w.setFingertipFriction(id, {staticFriction, dynamicFriction});
          },
          py::arg("fingertip"), py::arg("static_friction"), py::arg("dynamic_friction"))
      .def("fingertip_force", &World::fingertipForce, py::arg("fingertip"),
           "Force the fingertip applied to the bodies in the last substep (N)")
      .def("fingertip_contact_count", &World::fingertipContactCount, py::arg("fingertip"))
      .def("set_body_contact", &World::setBodyContact, py::arg("body"), py::arg("settings"))
      .def("body_contact", &World::bodyContact, py::arg("body"))
      .def("set_pair_contact", &World::setPairContact, py::arg("a"), py::arg("b"), py::arg("enabled"),
           "Switches contact between two different bodies off (or back on)")
      .def("body_contact_force", &World::bodyContactForce, py::arg("on"), py::arg("by"),
           "Force body `by`'s contacts applied to body `on` in the last substep (N)")
      .def("attach", &World::attach, py::arg("particle"), py::arg("target"), py::arg("compliance") = 0.0f,
           py::arg("axes") = Vec3(Vec3::Ones()), py::arg("damping") = 0.0f,
           "Holds a particle (world index) at target; returns the attachment's id")
      .def("particle_index", &World::particleIndex, py::arg("body"), py::arg("local"))
      .def("move_attachment", &World::moveAttachment, py::arg("attachment"), py::arg("goal"))
      .def("detach", &World::detach, py::arg("attachment"))
      .def("attachment_force", &World::attachmentForce, py::arg("attachment"))
      .def(
          "take_events",
          [](World& w) {
            py::list out;
            for (const SimEvent& e : w.takeEvents()) out.append(py::make_tuple(e.step, e.body, e.message));
            return out;
          },
          "(step, body, message) of what happened since the last call, e.g. a body frozen after a NaN");
}

}  // namespace vrd::python
