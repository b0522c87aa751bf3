#include "modules/graphs/module.h"

#include <cmath>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/world.h"
#include "modules/collision/rows.h"  // DistanceRow: a plain struct, no FCL
#include "modules/force_sensor/force_sensor.h"
#include "modules/proximity/proximity_sensor.h"  // readings: inline lookups, nothing linked

namespace swarmsim::graphs {

namespace {

double ComponentOf(const Vec3& v, Component c) {
  switch (c) {
    case Component::kX:
    case Component::kRoll: return v.x;
    case Component::kY:
    case Component::kPitch: return v.y;
    case Component::kZ:
    case Component::kYaw: return v.z;
    case Component::kNorm: return v.Norm();
    case Component::kNone: break;
  }
  return NAN;
}

// The value one stream reads now (nan: no reading).
double Read(const Scene& scene, const StreamSpec& s, uint32_t slot) {
  if (slot == kNoSlot) return NAN;
  switch (s.kind) {
    case StreamKind::kPosition: return ComponentOf(scene.world_pose_at(slot).p, s.component);
    case StreamKind::kOrientation:
      return ComponentOf(scene.world_pose_at(slot).q.RollPitchYaw(), s.component);
    case StreamKind::kVelocity: return ComponentOf(scene.linear_velocity_at(slot), s.component);
    case StreamKind::kAngularVelocity:
      return ComponentOf(scene.angular_velocity_at(slot), s.component);
    case StreamKind::kJoint: return scene.joints()[scene.row_at(slot)].position;
    case StreamKind::kJointVelocity: return scene.joints()[scene.row_at(slot)].velocity;
    case StreamKind::kProximity: {
      const ProximitySensorData* p = proximity::FindSensor(scene, scene.IdAt(slot));
      return p != nullptr && p->detected ? p->distance : NAN;
    }
    case StreamKind::kForce:
    case StreamKind::kTorque: {
      const ForceSensorData& f = force_sensor::RowsOf(scene)->rows[scene.row_at(slot)];
      if (!f.has_reading) return NAN;
      if (f.broken) return 0.0;  // as sim.readForceSensor reads a broken link
      return ComponentOf(s.kind == StreamKind::kForce ? f.force : f.torque, s.component);
    }
    case StreamKind::kDistance: {
      const auto& rows =
          static_cast<const Rows<collision::DistanceRow>&>(*scene.rows(scene.type_at(slot)));
      const collision::DistanceRow& d = rows.rows[scene.row_at(slot)];
      return d.found ? d.distance : NAN;
    }
    case StreamKind::kScript: break;
  }
  return NAN;
}

}  // namespace

ObjectId ResolveStream(const Scene& scene, ObjectId graph, const StreamSpec& stream,
                       std::string* problem) {
  const ObjectId id = scene.FindObject(stream.path, graph);
  if (id.IsNull()) {
    *problem =
        "'" + stream.path + "' matches no object" + scene.ExplainMissingPath(stream.path, graph);
    // './' looks below the graph; the graph's siblings are ':/' away.
    if (stream.path.starts_with("./")) {
      const std::string in_model = ":/" + stream.path.substr(2);
      if (!scene.FindObject(in_model, graph).IsNull())
        *problem +=
            " ('./' looks below the graph: did you mean '" + in_model + "', in the graph's model?)";
    } else if (stream.path.starts_with(":/") && stream.path.find('/', 2) == std::string::npos &&
               scene.instance_of(graph) >= 0) {
      *problem += " (the model's root is ':' itself, named after the copy)";
    }
    return {};
  }
  const ObjectType type = scene.type(id);
  const char* want = nullptr;
  switch (stream.kind) {
    case StreamKind::kJoint:
    case StreamKind::kJointVelocity:
      if (type != ObjectType::kJoint) want = "joint";
      break;
    case StreamKind::kProximity:
      if (!proximity::IsSensorAt(scene, scene.SlotOf(id))) want = proximity::kSensorTypeName;
      break;
    case StreamKind::kForce:
    case StreamKind::kTorque: {
      ObjectType force;
      if (!force_sensor::FindType(scene, &force) || type != force) want = kForceSensorTypeName;
      break;
    }
    case StreamKind::kDistance: {
      ObjectType distance;
      if (!scene.FindType("distance", &distance) || type != distance) want = "distance";
      break;
    }
    default: break;
  }
  if (want != nullptr) {
    *problem = "'" + stream.path + "' is a " + scene.type_name(type) + ", not a " + want;
    return {};
  }
  return id;
}

const Series* GraphModule::Find(ObjectId id) const {
  const auto it = by_id_.find(static_cast<uint64_t>(id.ToInteger()));
  return it == by_id_.end() ? nullptr : series_[it->second].get();
}

// The series of every graph in the scene (new ones begin), their streams'
// objects, and which robot samples each.
void GraphModule::Refresh(Scene* scene) {
  version_ = scene->structure_version();
  if (!have_type_) have_type_ = scene->FindType("graph", &type_);
  if (!have_type_) return;
  for (auto& s : series_) s->alive = false;
  by_robot_.assign(scene->instances().size() + 1, {});
  const auto& rows = static_cast<const Rows<GraphRow>&>(*scene->rows(type_));
  for (uint32_t r = 0; r < rows.size(); ++r) {
    const uint32_t slot = rows.owners[r];
    const ObjectId id = scene->IdAt(slot);
    const uint64_t key = static_cast<uint64_t>(id.ToInteger());
    auto it = by_id_.find(key);
    if (it == by_id_.end()) {
      auto s = std::make_unique<Series>();
      s->id = key;
      s->path = scene->PathOf(id);
      // The file: the path without its leading '/', made unique ("[1]").
      std::string file = s->path.substr(1);
      for (int k = 1; files_.count(file) != 0; ++k)
        file = s->path.substr(1) + "[" + std::to_string(k) + "]";
      files_.insert(file);
      s->file = file;
      s->settings = rows.rows[r];
      s->settings.script_values.clear();
      s->instance = scene->instance_of_at(slot);
      it = by_id_.emplace(key, series_.size()).first;
      series_.push_back(std::move(s));
    }
    Series& s = *series_[it->second];
    s.alive = true;
    s.row = r;
    // Streams whose object is gone read nan (the world file's paths were
    // checked when it loaded).
    s.sources.assign(s.settings.streams.size(), kNoSlot);
    for (size_t i = 0; i < s.settings.streams.size(); ++i) {
      const StreamSpec& spec = s.settings.streams[i];
      if (spec.kind == StreamKind::kScript) continue;
      std::string problem;
      const ObjectId target = ResolveStream(*scene, id, spec, &problem);
      if (target.IsNull()) continue;
      s.sources[i] = target.index();
      // A joint's unit, now that its type is known.
      if (spec.kind == StreamKind::kJoint || spec.kind == StreamKind::kJointVelocity) {
        const bool linear = scene->joint(target).type() == JointType::kPrismatic;
        s.settings.streams[i].unit =
            spec.kind == StreamKind::kJoint ? (linear ? "m" : "rad") : (linear ? "m/s" : "rad/s");
      }
    }
    const int instance = scene->instance_of_at(slot);
    by_robot_[instance >= 0 ? instance : by_robot_.size() - 1].push_back(
        static_cast<uint32_t>(it->second));
  }
}

void GraphModule::Sample(Scene* scene, Series* series, double time) {
  Series& s = *series;
  auto& rows = static_cast<Rows<GraphRow>&>(*scene->rows(type_));
  GraphRow& row = rows.rows[s.row];
  if (row.script_values.size() != s.settings.streams.size())  // a row not read from a file
    row.script_values.assign(s.settings.streams.size(), NAN);
  const size_t width = s.width();
  const size_t capacity = static_cast<size_t>(s.settings.buffer);
  double* out = nullptr;
  if (s.count < capacity) {
    s.data.resize(s.data.size() + width);
    out = &s.data[s.data.size() - width];
    ++s.count;
  } else if (s.settings.cyclic) {
    out = &s.data[s.first * width];  // overwrites the oldest
    s.first = (s.first + 1) % capacity;
    ++s.dropped;
  } else {
    ++s.dropped;
  }
  for (size_t i = 0; i < s.settings.streams.size(); ++i) {
    const StreamSpec& spec = s.settings.streams[i];
    if (out != nullptr)
      out[i + 1] = spec.kind == StreamKind::kScript ? row.script_values[i]
                                                    : Read(*scene, spec, s.sources[i]);
    row.script_values[i] = NAN;  // a script sets each sample's value
  }
  if (out != nullptr) out[0] = time;
}

bool GraphModule::SaveState(const World& world, StateWriter*) const {
  ObjectType type;
  const Scene& scene = world.scene();
  return !(scene.FindType("graph", &type) && scene.rows(type) != nullptr &&
           scene.rows(type)->size() > 0);
}

void GraphModule::Start(World* world) {
  Refresh(&world->scene());
  std::vector<MetricSample> none;
  Record(*world, &none);
}

void GraphModule::Record(const World& world, std::vector<MetricSample>*) {
  Scene& scene = world_->scene();
  if (version_ != scene.structure_version()) Refresh(&scene);
  if (!have_type_ || scene.rows(type_)->size() == 0) return;
  const int64_t step = world.step_count();
  const double time = world.time();
  const auto sample_robot = [&](size_t robot) {
    for (uint32_t index : by_robot_[robot]) {
      Series& s = *series_[index];
      if (step % s.settings.every == 0) Sample(&scene, &s, time);
    }
  };
  const int64_t robots = static_cast<int64_t>(by_robot_.size()) - 1;
  world_->scheduler().ParallelFor(0, robots, kRobotGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) sample_robot(static_cast<size_t>(r));
  });
  sample_robot(by_robot_.size() - 1);
}

}  // namespace swarmsim::graphs
