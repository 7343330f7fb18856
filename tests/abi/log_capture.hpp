// SPDX-License-Identifier: MIT
// Test support for the ABI tests: captures the default spdlog logger's
// output (debug level and up) while alive.
#pragma once

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <sstream>

namespace domel::test {

struct LogCapture {
  LogCapture() : old(spdlog::default_logger()) {
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(text);
    auto logger = std::make_shared<spdlog::logger>("capture", sink);
    logger->set_level(spdlog::level::debug);
    spdlog::set_default_logger(logger);
  }
  ~LogCapture() { spdlog::set_default_logger(old); }
  std::ostringstream text;
  std::shared_ptr<spdlog::logger> old;
};

}  // namespace domel::test
