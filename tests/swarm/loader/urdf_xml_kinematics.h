// A URDF's kinematics read straight from its XML (tinyxml2), independently
// of the importer: the reference the URDF tests compare the scene against.
#pragma once

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "framework/math.h"

namespace swarmsim::testing {

struct XmlJoint {
  std::string name, type, parent, child;
  Pose origin;
  Vec3 axis{1, 0, 0};
  std::string mimic;  // master joint, or ""
  double multiplier = 1, offset = 0;
};

inline Vec3 ParseVec(const char* text, Vec3 fallback) {
  if (!text) return fallback;
  std::istringstream in(text);
  Vec3 v;
  in >> v.x >> v.y >> v.z;
  return v;
}

// The robot's <joint> elements (not those inside <transmission>); its
// links' names into `links` if given.
inline std::vector<XmlJoint> ReadJoints(const std::string& path,
                                        std::vector<std::string>* links = nullptr) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.LoadFile(path.c_str()), tinyxml2::XML_SUCCESS) << path;
  std::vector<XmlJoint> out;
  const tinyxml2::XMLElement* robot = doc.RootElement();
  if (robot == nullptr) return out;
  if (links != nullptr)
    for (auto* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link"))
      links->push_back(e->Attribute("name"));
  for (auto* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
    XmlJoint j;
    j.name = e->Attribute("name");
    j.type = e->Attribute("type");
    j.parent = e->FirstChildElement("parent")->Attribute("link");
    j.child = e->FirstChildElement("child")->Attribute("link");
    if (auto* o = e->FirstChildElement("origin")) {
      const Vec3 rpy = ParseVec(o->Attribute("rpy"), {});
      j.origin = {ParseVec(o->Attribute("xyz"), {}), Quat::FromRollPitchYaw(rpy.x, rpy.y, rpy.z)};
    }
    if (auto* a = e->FirstChildElement("axis")) j.axis = ParseVec(a->Attribute("xyz"), {1, 0, 0});
    if (auto* m = e->FirstChildElement("mimic")) {
      j.mimic = m->Attribute("joint");
      m->QueryDoubleAttribute("multiplier", &j.multiplier);
      m->QueryDoubleAttribute("offset", &j.offset);
    }
    out.push_back(j);
  }
  return out;
}

// Pose of every link in the root link's frame for joint values `q`
// (floating and planar joints at their origin, as imported).
inline std::map<std::string, Pose> ForwardKinematics(const std::vector<XmlJoint>& joints,
                                                     const std::map<std::string, double>& q) {
  std::map<std::string, Pose> X;
  for (const XmlJoint& j : joints) X.emplace(j.parent, Pose{});  // the root stays at identity
  for (const XmlJoint& j : joints) X.erase(j.child);
  for (size_t pass = 0; pass <= joints.size(); ++pass)
    for (const XmlJoint& j : joints) {
      if (!X.contains(j.parent) || X.contains(j.child)) continue;
      const double v = q.contains(j.name) ? q.at(j.name) : 0.0;
      Pose motion;
      if (j.type == "revolute" || j.type == "continuous") motion.q = Quat::FromAxisAngle(j.axis, v);
      if (j.type == "prismatic") motion.p = j.axis.Normalized() * v;
      X[j.child] = X[j.parent] * j.origin * motion;
    }
  return X;
}

}  // namespace swarmsim::testing
