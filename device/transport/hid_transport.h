// HidTransport: the LP3500 over USB HID through hidapi's Linux hidraw backend. Enumerates by vendor
// and product id, opens by path or serial number, reads input reports with a timeout and exchanges
// feature reports (firmware identity, calibration).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "device/transport/device_transport.h"
#include "device/transport/host_clock.h"

struct hid_device_;

namespace resecto {

/// One HID device as enumerated.
struct HidDeviceInfo {
  std::string path;  ///< hidraw node, e.g. /dev/hidraw3
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string serial_number;
  std::string manufacturer;
  std::string product;
  std::uint16_t release_number = 0;
  int interface_number = -1;
};

/// Which device to open. Vendor/product 0 match any; an empty path or serial matches any.
struct HidSelector {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string path;           ///< when set, open exactly this node
  std::string serial_number;  ///< when set (and no path), the first match with this serial
};

/// Every HID device matching `vendor_id`/`product_id` (0 = any), sorted by path for a stable order.
/// An error when hidapi cannot be initialised.
Result<std::vector<HidDeviceInfo>> enumerate_hid_devices(std::uint16_t vendor_id, std::uint16_t product_id);

/// The hidapi library's version string, to show it is really linked.
std::string hidapi_version();

/// Ok when `path` is a hidraw character device; hidapi's hid_open_path crashes (frees a bad pointer)
/// when handed a regular file, /dev/null or /dev/zero, so every path is checked before it is opened.
Status check_hidraw_node(const std::string& path);

/// hidapi-backed transport. Not copyable; closes the device on destruction.
class HidTransport final : public DeviceTransport {
 public:
  explicit HidTransport(HidSelector selector);
  ~HidTransport() override;
  HidTransport(const HidTransport&) = delete;
  HidTransport& operator=(const HidTransport&) = delete;

  Status open() override;
  void close() override;
  bool is_open() const override { return device_ != nullptr; }
  Result<std::size_t> read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) override;
  Result<std::size_t> get_feature_report(std::uint8_t report_id, std::span<std::uint8_t> buffer) override;
  Status send_feature_report(std::span<const std::uint8_t> report) override;
  std::string describe() const override;

 private:
  std::string last_error() const;

  HidSelector selector_;
  std::string opened_path_;
  hid_device_* device_ = nullptr;
};

}  // namespace resecto
