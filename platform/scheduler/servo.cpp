// SPDX-License-Identifier: MIT
#include "scheduler/servo.hpp"

#include "core/archive.hpp"
#include "loop/ranks.hpp"
#include "subdomain/subdomain.hpp"

#include <algorithm>

namespace domel::platform {

void WallServos::update(double t, const std::vector<std::unique_ptr<Subdomain>>& subdomains, RunRanks& ranks) {
  std::vector<double> load(3 * servos.size(), 0.0);  // on this rank's particles
  for (std::size_t k = 0; k < servos.size(); ++k)
    for (const auto& sd : subdomains) {
      double g[3];
      sd->wall_load(servos[k].wall, g);
      for (int a = 0; a < 3; ++a) load[3 * k + a] += g[a];
    }
  load = ranks.sum_in_rank_order(load);
  for (std::size_t k = 0; k < servos.size(); ++k) {
    WallServo& s = servos[k];
    const double* f = &load[3 * k];
    // the particles push the wall back against its direction
    s.measured = 0.0 - (f[0] * s.direction[0] + f[1] * s.direction[1] + f[2] * s.direction[2]);
    const double vmax = s.state->max_velocity;
    const double v = t >= s.start && t < s.end ? std::clamp(s.gain * (s.force - s.measured), -vmax, vmax) : 0.0;
    // past its end the travel stops where it stood at the end (no jump when
    // the end falls inside a macro step)
    s.state->set_velocity(std::min(t, s.end), v);
  }
}

std::vector<std::string> WallServos::columns() const {
  std::vector<std::string> c;
  for (const WallServo& s : servos) {
    c.push_back(s.name + ".servo_force");
    c.push_back(s.name + ".servo_travel");
  }
  return c;
}

void WallServos::append_values(double t, std::vector<double>& row) const {
  for (const WallServo& s : servos) {
    row.push_back(s.measured);
    row.push_back(s.state->travel(std::clamp(t, s.start, s.end)));
  }
}

void WallServos::fields(CheckpointFields& f) {
  std::vector<double> v;  // per servo: travel reference, its time, velocity, the load measured
  for (const WallServo& s : servos) v.insert(v.end(), {s.state->s_ref, s.state->t_ref, s.state->velocity, s.measured});
  f("state", v);
  if (!f.loading()) return;
  if (v.size() != 4 * servos.size())
    f.reader().fail(f.prefix() + "state", "holds " + std::to_string(v.size() / 4) + " servos, this scenario has " +
                                              std::to_string(servos.size()));
  for (std::size_t k = 0; k < servos.size(); ++k) {
    servos[k].state->s_ref = v[4 * k];
    servos[k].state->t_ref = v[4 * k + 1];
    servos[k].state->velocity = v[4 * k + 2];
    servos[k].measured = v[4 * k + 3];
  }
}

void WallServos::save(ArchiveWriter& w, const std::string& prefix) {
  save_fields(w, prefix, [&](CheckpointFields& f) { fields(f); });
}

void WallServos::load(const ArchiveReader& r, const std::string& prefix) {
  load_fields(r, prefix, [&](CheckpointFields& f) { fields(f); });
}

}  // namespace domel::platform
