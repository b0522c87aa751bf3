#include "swarm/sweep/mpi.h"

#include <unistd.h>

#include <ostream>

#include "framework/error.h"
#include "swarm/sweep/coordinator.h"

#ifdef SWARMSIM_HAVE_MPI
#include <mpi.h>

#include <nlohmann/json.hpp>
#endif

namespace swarmsim {

#ifndef SWARMSIM_HAVE_MPI

bool MpiAvailable() { return false; }
int RunSweepMpi(const SweepOptions&, std::ostream&, std::ostream&) {
  throw Error(
      "this swarmsim was built without MPI (install libopenmpi-dev and rebuild); "
      "use --shard i/n and `swarmsim merge` instead");
}

#else

namespace {

constexpr int kTagRequest = 1;  // worker -> 0: "give me a run" (+ the last result, if any)
constexpr int kTagRun = 2;      // 0 -> worker: a run (JSON)
constexpr int kTagStop = 3;     // 0 -> worker: no more runs

nlohmann::json ToJson(const RunOutcome& o) {
  nlohmann::json j{{"id", o.id},           {"ok", o.ok},         {"error", o.error},
                   {"wall_s", o.wall_s},   {"steps", o.steps},   {"robots", o.robots},
                   {"hash", o.state_hash}, {"worker", o.worker}, {"final", o.final_metrics}};
  nlohmann::json s = nlohmann::json::array();
  for (const SeriesPoint& p : o.series) s.push_back({p.metric, p.step, p.time, p.value});
  j["series"] = std::move(s);
  j["machine"] = o.machine;
  return j;
}

RunOutcome FromJson(const nlohmann::json& j) {
  RunOutcome o;
  o.id = j.at("id");
  o.ok = j.at("ok");
  o.error = j.at("error");
  o.machine = j.value("machine", false);
  o.wall_s = j.at("wall_s");
  o.steps = j.at("steps");
  o.robots = j.at("robots");
  o.state_hash = j.at("hash");
  o.worker = j.at("worker");
  o.final_metrics = j.at("final").get<std::map<std::string, double> >();
  for (const auto& p : j.at("series"))
    o.series.push_back(
        {p[0].get<std::string>(), p[1].get<int64_t>(), p[2].get<double>(), p[3].get<double>()});
  return o;
}

void Send(const std::string& text, int dest, int tag) {
  MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, dest, tag, MPI_COMM_WORLD);
}

std::string Receive(int source, int* tag, int* from) {
  MPI_Status status;
  MPI_Probe(source, MPI_ANY_TAG, MPI_COMM_WORLD, &status);
  int count = 0;
  MPI_Get_count(&status, MPI_CHAR, &count);
  std::string text(static_cast<size_t>(count), '\0');
  MPI_Recv(text.data(), count, MPI_CHAR, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  *tag = status.MPI_TAG;
  *from = status.MPI_SOURCE;
  return text;
}

// Rank 0's view of the other ranks.
class MpiWorkers : public RemoteWorkers {
 public:
  explicit MpiWorkers(int size) : live_(size - 1), holding_(static_cast<size_t>(size), false) {}

  void Service(const std::function<std::optional<GridRun>()>& next,
               const std::function<void(RunOutcome)>& done) override {
    while (true) {
      int flag = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &flag, &status);
      if (!flag) return;
      int tag = 0, from = 0;
      const std::string text = Receive(status.MPI_SOURCE, &tag, &from);
      if (!text.empty()) {
        holding_[static_cast<size_t>(from)] = false;
        --running_;
        done(FromJson(nlohmann::json::parse(text)));
      }
      if (std::optional<GridRun> run = next()) {
        nlohmann::json params = nlohmann::json::array();
        for (const auto& [name, value] : run->params) params.push_back({name, value});
        Send(
            nlohmann::json{
                {"id", run->id}, {"point", run->point}, {"seed", run->seed}, {"params", params}}
                .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
            from, kTagRun);
        holding_[static_cast<size_t>(from)] = true;
        ++running_;
      } else {
        Send("", from, kTagStop);
        --live_;
      }
    }
  }
  bool Busy() const override { return live_ > 0; }
  int Running() const override { return running_; }

 private:
  int live_;  // ranks not yet told to stop
  int running_ = 0;
  std::vector<bool> holding_;
};

// A rank other than 0: ask for a run, run it, send the result with the next request.
int WorkerLoop(const SweepOptions& o) {
  const WorkerConfig config = MakeWorkerConfig(o, 1);
  RunPool pool(config, 1);
  std::string result;
  while (true) {
    Send(result, 0, kTagRequest);
    int tag = 0, from = 0;
    const std::string text = Receive(0, &tag, &from);
    if (tag == kTagStop) break;
    const nlohmann::json j = nlohmann::json::parse(text);
    GridRun run;
    run.id = j.at("id");
    run.point = j.at("point");
    run.seed = j.at("seed");
    for (const auto& p : j.at("params")) run.params.emplace_back(p[0], p[1]);
    pool.Start(run);
    std::vector<RunOutcome> ended;
    while (ended.empty()) ended = pool.Poll(1.0);
    result = ToJson(ended.front()).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  }
  return 0;
}

}  // namespace

bool MpiAvailable() { return true; }

int RunSweepMpi(const SweepOptions& options, std::ostream& out, std::ostream& err) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) MPI_Init(nullptr, nullptr);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int code = 0;
  try {
    if (rank == 0) {
      MpiWorkers workers(size);
      code = CoordinateSweep(options, size > 1 ? &workers : nullptr, out, err);
    } else {
      code = WorkerLoop(options);
    }
  } catch (const std::exception& e) {
    // One rank's error (bad input, an unusable database) ends them all.
    err << "error: " << e.what() << "\n" << std::flush;
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  MPI_Finalize();
  return code;
}

#endif

}  // namespace swarmsim
