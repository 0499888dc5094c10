// DeviceSample: one validated, calibrated device reading as the link thread hands it to the core
// through the SPSC ring, or a connection event (the core must learn of an unplug in order, between
// the samples around it).
#pragma once

#include <cstdint>

#include "resecto/lp3500_protocol.h"
#include "rtcore/kinematics/tool_kinematics.h"

namespace resecto {

/// What a ring entry means.
enum class LinkEvent : std::uint8_t {
  kSample = 0,        ///< a device reading
  kConnected = 1,     ///< the device (re)appeared; readings follow
  kDisconnected = 2,  ///< transport error or silence past the timeout; hold the tool
};

/// Pedal bits as the board sends them (the protocol's, lp3500_protocol.h).
inline constexpr std::uint8_t kPedalCut = LP3500_PEDAL_CUT;
inline constexpr std::uint8_t kPedalCoagulate = LP3500_PEDAL_COAGULATE;

/// A reading in SI units with its provenance. Trivially copyable: the ring moves it by value.
struct DeviceSample {
  LinkEvent event = LinkEvent::kSample;
  std::uint8_t pedals = 0;          ///< kPedal* bits
  std::uint16_t status = 0;         ///< the board's LP3500_STATUS_* flags for this report
  std::uint64_t sequence = 0;       ///< the board's 32-bit sequence number, unwrapped to 64 bits
  std::uint64_t device_time_us = 0; ///< board clock at the end of the report's period
  std::int64_t host_time_ns = 0;    ///< host clock when the report was read
  DeviceJoints joints;              ///< calibrated joint values
};

}  // namespace resecto
