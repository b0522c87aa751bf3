// The Python binding's IR messages (modules/ir_messaging, the Kilobot's
// messaging; swarm/python/world.cc): what each robot's transceiver heard in
// the last sense phase as flat arrays (the form of range_and_bearing and
// blob_cameras), and the messages Python queues for the next sense phase.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarm/python/arrays.h"

namespace swarmsim::python {

// The transceiver `name` ("": the robots' only one) of each robot of
// `layout`, and a name per robot for messages ("robot 'kilobot#3'").
// ValueError when the robots have none, or several and no name is given.
std::vector<uint32_t> IrTransceivers(const Scene& scene, const ModelLayout& layout,
                                     const std::string& name, std::vector<std::string>* who);

// What the transceivers at `slots` (one per robot) heard in the last sense
// phase: robot i's messages are rows offsets[i] to offsets[i + 1] - 1, in
// arrival order: offsets (N + 1, int64), distance (M, float64: the
// receiver's estimate, m), sender (M, int64: the sending robot's index, -1
// for a transceiver of no robot), size (M, int64: the message's bytes),
// data (M x the largest size, uint8, zero-padded), and sent (N, bool: the
// robot's own queued message went out). `out`: a dict this function
// returned before (or None): its arrays are filled in place where dtype
// and shape still fit (offsets and sent always do), replaced otherwise,
// and the same dict is returned.
py::dict IrMessages(const Scene& scene, const std::vector<uint32_t>& slots, const py::object& out);

// Queues row i of `data` ((N, k) bytes 0..255, k from 1 to the payload
// size) as robot i's message for the next sense phase, for the robots whose
// `send` (None: all; else (N,) bools) is true. Checked whole first:
// ValueError (shape, values, sizes), TypeError (not integers).
void SendIrMessages(Scene* scene, const std::vector<uint32_t>& slots,
                    const std::vector<std::string>& who, const py::object& data,
                    const py::object& send);

}  // namespace swarmsim::python
