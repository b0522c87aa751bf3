// URDF import (`model: robot.urdf` in a world's models entry): a URDF file
// read with urdfdom (and tinyxml2 for the line of each element) into the
// objects of a model, once per world; the urdf:: types stay in urdf.cc.
//
// Links become shapes: each rigid group of links (joined by fixed joints)
// is one body, a non-collidable carrier shape at the group's top link frame
// holding the group's mass, centre of mass and inertia about it
// (urdf_inertia.h: merged, repaired, defaulted); each link's
// <collision> and <visual> geometry are shapes below it (visuals do not
// collide). Moving joints become joints whose z axis is the URDF axis;
// mimic joints become dependent joints. worlds/README.md ("URDF models")
// documents the mapping.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "swarm/loader/mesh.h"
#include "swarm/loader/model.h"

namespace swarmsim::loader {

// The mass and inertia of a body that can move and has no mass (its links
// have no <inertial> or mass 0): at its top link's origin.
inline constexpr double kUrdfDefaultMass = 0.1;      // kg
inline constexpr double kUrdfDefaultInertia = 1e-4;  // kg m^2, about each axis
// A body of point masses only (zero <inertia>): mass x this about each axis
// (the default body's squared radius of gyration).
inline constexpr double kUrdfPointMassGyration = kUrdfDefaultInertia / kUrdfDefaultMass;  // m^2
// An <inertia> whose diagonal is within mass x this of zero is a point mass.
inline constexpr double kUrdfPointMassTolerance = 1e-12;  // m^2
inline constexpr double kUrdfDefaultEffort = 100;         // N or N m, a <limit effort="0">
inline constexpr double kUrdfDefaultVelocity = 10;        // rad/s or m/s, no <limit velocity>
inline constexpr double kUrdfCarrierRadius = 0.001;       // m, the body carrier's sphere

struct UrdfImport {
  ObjectSpec root;                    // the root link's object, base fixed (not dynamic)
  std::string name;                   // the robot's name, usable as a model name
  std::vector<std::string> summary;   // what was imported, for `swarmsim describe`
  std::vector<std::string> warnings;  // one per kind of thing ignored or defaulted
  // Joints that are no joint objects (fixed, planar, floating: their links
  // are merged or free), by the name a moving joint of theirs would have ->
  // their kind ("fixed"), for messages naming them.
  std::map<std::string, std::string> merged_joints;
};

// Reads the URDF at `path` (`text` as the world names it, `where` the
// file:line:column naming it). package://PKG/REST URIs resolve in the
// package holding the URDF (a folder above it whose package.xml names PKG),
// then through `package_path` (each folder: PKG below it, a package.xml
// naming PKG in it or in a subfolder one or two levels down); file:// URIs
// are percent-decoded. Throws swarmsim::Error naming the file,
// the element and its line for malformed input.
UrdfImport ImportUrdf(const std::filesystem::path& path, const std::string& where,
                      const std::string& text,
                      const std::vector<std::filesystem::path>& package_path, MeshCache* meshes);

// Whether `text` names a URDF file (.urdf, any case).
bool IsUrdfFile(const std::string& text);

// `root` with a floating base: its root body simulated (dynamic) when it has
// a mass. Throws (naming `where`) when the root group has none.
ObjectSpec WithFloatingBase(const ObjectSpec& root, const std::string& where);

}  // namespace swarmsim::loader
