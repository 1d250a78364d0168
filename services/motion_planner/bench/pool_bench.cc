// Motion planner node over DDS: throughput of concurrent clients with a pool of 1 vs 2 planners,
// and the latency of a request with object overrides against the same request without.
//
// In one process, on an isolated DDS domain: a MotionPlannerNode (disc robot of the NAMO
// benchmark, 0.354 m, the shipped config's planner parameters) mirrors a NAMO world published by
// a WorldPublisher; every planner of the pool is prepared (MotionPlanner::prepare, as the node
// does after a world update) before timing. Queries: fixed-seed random base poses whose disc is
// clear of static objects, lazy mode, movable_cost_weight 1.
//  - latency: one client, per query the plain request, the same again (the control: warm), then
//    with the first blocking movable moved 3 m (an override), then removed; client round trips.
//  - throughput: `--clients` clients (threads, own RpcClient each) share the query list; wall
//    time from the first request to the last reply, for `--planners` 1 and 2 (a node each).
//
// Usage: tamp_motion_planner_pool_bench [--world FILE.svg|json] [--queries 40] [--clients 2]
#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <numeric>
#include <random>
#include <thread>

#include "motion_planner_node.h"
#include "tamp/collision/scene.h"
#include "tamp/core/paths.h"
#include "tamp/core/stats.h"
#include "tamp/dds/participant.h"
#include "tamp/dds/rpc.h"
#include "tamp/world/namo.h"

namespace mp = tamp::motion_planner;
using namespace tamp;

namespace {

double nowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

struct Query {
  Pose2D start, goal;
};

std::vector<Query> makeQueries(const world::World& w, double radius, int n, std::uint32_t seed) {
  collision::Scene scene(w);
  scene.setRobot(collision::RobotGeometry::disc(radius, 1.0));
  const Aabb b = w.bounds();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()),
      uth(-M_PI, M_PI);
  auto freePose = [&] {
    for (int k = 0; k < 10000; ++k) {
      Pose2D p{ux(rng), uy(rng), uth(rng)};
      scene.setBasePose(p);
      if (!scene.robotInCollision(collision::Filter::staticOnly())) return p;
    }
    throw std::runtime_error("no free pose");
  };
  std::vector<Query> out;
  while (static_cast<int>(out.size()) < n) {
    Query q{freePose(), freePose()};
    if (std::hypot(q.goal.x - q.start.x, q.goal.y - q.start.y) < 2.0) continue;
    out.push_back(q);
  }
  return out;
}

msg::MotionRequest request(const Query& q) {
  msg::MotionRequest r;
  r.group(msg::GROUP_BASE);
  r.mode(msg::MOTION_LAZY);
  r.start_base(dds::toMsg(q.start));
  r.goal_type(msg::GOAL_BASE_POSE);
  r.goal_base(dds::toMsg(q.goal));
  r.movable_cost_weight(1.0);
  return r;
}

std::unique_ptr<mp::MotionPlannerNode> makeNode(int domain, int planners) {
  auto cfg = mp::loadNodeConfig(configDir() / "services" / "motion_planner.yaml");
  if (!cfg) throw std::runtime_error(cfg.error().toString());
  cfg->robot = "disc";
  cfg->disc_radius = 0.354;
  cfg->planners = planners;
  dds::ServiceArgs args;
  args.name = "motion_planner_bench";
  args.domain_id = domain;
  auto node = mp::MotionPlannerNode::create(args, *cfg);
  if (!node) throw std::runtime_error(node.error().toString());
  return std::move(*node);
}

/// Waits until the node mirrors the world, then prepares every planner.
void warm(mp::MotionPlannerNode& node, dds::RpcClient<msg::MotionRequest, msg::MotionReply>& client,
          const Query& q, uint64_t version) {
  msg::MotionRequest r = request(q);
  r.world_version(version);
  auto rep = client.call(r, dds::CallOptions{60.0, {}});
  if (!rep) throw std::runtime_error(rep.error().toString());
  for (int i = 0; i < 200; ++i) {
    const auto preps = node.prepareIfWorldChanged();
    if (std::none_of(preps.begin(), preps.end(), [](const auto& p) { return p.has_value(); }))
      break;
  }
}

void printStats(const char* name, std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  std::printf("  %-22s n=%3zu  p50 %7.1f ms  p90 %7.1f ms  mean %7.1f ms\n", name, ms.size(),
              interpolatedPercentile(ms, 0.5), interpolatedPercentile(ms, 0.9),
              std::accumulate(ms.begin(), ms.end(), 0.0) / std::max<std::size_t>(1, ms.size()));
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path world_file = std::filesystem::path(TAMP_BENCHMARKS_DIR) / "namo" /
                                     "moghaddam_planning_2016_benchmark" /
                                     "moghaddam_planning_2016_benchmark_07.svg";
  int queries = 40, clients = 2;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--world")
      world_file = argv[i + 1];
    else if (a == "--queries")
      queries = std::stoi(argv[i + 1]);
    else if (a == "--clients")
      clients = std::stoi(argv[i + 1]);
    else {
      std::cerr << "unknown option " << a << "\n";
      return 2;
    }
  }
  auto nw = world::loadNamo(world_file);
  if (!nw) {
    std::cerr << nw.error().toString() << "\n";
    return 1;
  }
  const int domain = 20 + static_cast<int>(::getpid() % 200);
  auto participant =
      dds::Participant::create(dds::ParticipantOptions{domain, dds::kProfileDefault, "bench", {}});
  if (!participant) {
    std::cerr << participant.error().toString() << "\n";
    return 1;
  }
  dds::WorldPublisher publisher(*participant);
  if (Status s = publisher.publish(nw->world); !s) {
    std::cerr << s.error().toString() << "\n";
    return 1;
  }
  const auto qs = makeQueries(nw->world, 0.354, queries, 7);
  std::printf("world %s: %zu objects; %d queries; load before: %s\n", world_file.filename().c_str(),
              nw->world.objects().size(), queries, loadavg().c_str());

  // ---- latency with and without overrides (1 client, 2 planners) ----
  {
    auto node = makeNode(domain, 2);
    dds::RpcClient<msg::MotionRequest, msg::MotionReply> client(*participant,
                                                                dds::services::kMotion);
    warm(*node, client, qs.front(), publisher.publishedVersion());
    std::vector<double> plain, repeat, moved, removed;
    int with_blocking = 0;
    for (const Query& q : qs) {
      msg::MotionRequest r = request(q);
      double t0 = nowS();
      auto rep = client.call(r, dds::CallOptions{60.0, {}});
      plain.push_back((nowS() - t0) * 1e3);
      if (!rep || rep->status() != msg::MOTION_SOLVED || rep->blocking().empty()) continue;
      ++with_blocking;
      t0 = nowS();
      auto again =
          client.call(r, dds::CallOptions{60.0, {}});  // the control: the same request, warm
      repeat.push_back((nowS() - t0) * 1e3);
      const std::string id = rep->blocking()[0].object_id();
      Eigen::Isometry3d pose = nw->world.object(id).pose;
      pose.translation().x() += 3.0;
      msg::ObjectOverride o;
      o.object_id(id);
      o.pose(dds::toMsg(pose));
      r.object_overrides().push_back(o);
      t0 = nowS();
      auto rm = client.call(r, dds::CallOptions{60.0, {}});
      moved.push_back((nowS() - t0) * 1e3);
      r.object_overrides()[0].removed(true);
      t0 = nowS();
      auto rr = client.call(r, dds::CallOptions{60.0, {}});
      removed.push_back((nowS() - t0) * 1e3);
      if (!rm || !rr || rm->status() != msg::MOTION_SOLVED || rr->status() != msg::MOTION_SOLVED) {
        std::fprintf(stderr, "override request failed\n");
      }
    }
    std::printf("latency (1 client, round trip; %d of %d queries cross a movable):\n",
                with_blocking, queries);
    printStats("plain (first)", plain);
    printStats("plain (repeated)", repeat);
    printStats("override: moved 3 m", moved);
    printStats("override: removed", removed);
  }

  // ---- throughput: `clients` concurrent clients, 1 vs 2 planners ----
  for (int planners : {1, 2}) {
    auto node = makeNode(domain, planners);
    std::vector<std::unique_ptr<dds::RpcClient<msg::MotionRequest, msg::MotionReply>>> cl;
    for (int c = 0; c < clients; ++c) {
      cl.push_back(std::make_unique<dds::RpcClient<msg::MotionRequest, msg::MotionReply>>(
          *participant, dds::services::kMotion));
    }
    warm(*node, *cl.front(), qs.front(), publisher.publishedVersion());
    std::atomic<int> next{0}, failed{0};
    std::vector<std::vector<double>> lat(static_cast<std::size_t>(clients));
    const double t0 = nowS();
    std::vector<std::thread> threads;
    for (int c = 0; c < clients; ++c) {
      threads.emplace_back([&, c] {
        for (int i = next++; i < queries; i = next++) {
          const double s = nowS();
          auto rep = cl[static_cast<std::size_t>(c)]->call(request(qs[static_cast<std::size_t>(i)]),
                                                           dds::CallOptions{120.0, {}});
          lat[static_cast<std::size_t>(c)].push_back((nowS() - s) * 1e3);
          if (!rep || rep->status() != msg::MOTION_SOLVED) ++failed;
        }
      });
    }
    for (auto& t : threads) t.join();
    const double wall = nowS() - t0;
    std::vector<double> all;
    for (const auto& l : lat) all.insert(all.end(), l.begin(), l.end());
    std::printf(
        "throughput, %d clients, %d planner(s): %d requests in %.2f s = %.1f req/s (%d not "
        "solved)\n",
        clients, planners, queries, wall, queries / wall, failed.load());
    printStats("round trip", all);
  }
  std::printf("load after: %s\n", loadavg().c_str());
  return 0;
}
