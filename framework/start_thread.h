// Starting a thread the program cannot do without (a run's watchdog, the
// recording's writer, the video's encoder, the viewer's server), with a
// message a user can act on when the system starts none.
#pragma once

#include <system_error>
#include <thread>
#include <utility>

#include "framework/error.h"

namespace swarmsim {

// "cannot start a thread for <what>: <why> (...)": what a std::system_error from
// std::thread means and where to look (the process limit, ulimit -u; the
// address-space limit, ulimit -v, against a thread's stack, ulimit -s).
std::string CannotStartThreadMessage(const char* what, const std::system_error& error);

// std::thread(f); swarmsim::Error naming `what` ("the run's watchdog") when
// the system starts no thread. std::thread's own std::system_error said
// "Resource temporarily unavailable" and nothing else, and escaped the
// handlers that write a failed run's summary.json.
template <class F>
std::thread StartThread(const char* what, F&& f) {
  try {
    return std::thread(std::forward<F>(f));
  } catch (const std::system_error& e) {
    throw Error(CannotStartThreadMessage(what, e));
  }
}

}  // namespace swarmsim
