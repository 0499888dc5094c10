#include "device/link/board_flags.h"

#include "resecto/lp3500_protocol.h"

namespace resecto {

void BoardFlagCounts::count(std::uint16_t status) {
  for (std::size_t e = 0; e < illegal_transitions.size(); ++e) {
    if (status & (LP3500_STATUS_ILLEGAL_ENCODER_0 << e)) ++illegal_transitions[e];
  }
  if (status & LP3500_STATUS_SHEATH_CLAMPED) ++sheath_clamped;
  if (status & LP3500_STATUS_LOOP_CLAMPED) ++loop_clamped;
  if (status & LP3500_STATUS_STALL) ++stalls;
  if (status & LP3500_STATUS_OVERRUN) ++overruns;
  if (status & LP3500_STATUS_NO_ADC_SAMPLE) ++no_adc_sample;
}

}  // namespace resecto
