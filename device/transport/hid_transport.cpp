// hidapi (hidraw backend) transport for the LP3500. hidapi's strings are wide; ours are UTF-8.
#include "device/transport/hid_transport.h"

#include <hidapi.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>
#include <cstdio>
#include <cwchar>
#include <mutex>

namespace resecto {
namespace {

std::string narrow(const wchar_t* text) {
  if (text == nullptr) return {};
  std::string out;
  for (; *text != L'\0'; ++text) {
    const auto c = static_cast<std::uint32_t>(*text);
    // UTF-8 by hand: hidapi's strings are short, and the C library's conversion depends on the locale.
    if (c < 0x80) {
      out += static_cast<char>(c);
    } else if (c < 0x800) {
      out += static_cast<char>(0xC0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3F));
    } else if (c < 0x10000) {
      out += static_cast<char>(0xE0 | (c >> 12));
      out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (c & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (c >> 18));
      out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  return out;
}

// hid_init is not thread-safe and must run once before any other call.
Status ensure_hidapi_initialised() {
  static std::once_flag once;
  static int init_result = 0;
  std::call_once(once, [] { init_result = hid_init(); });
  if (init_result != 0) return Error{"hidapi: hid_init failed: " + narrow(hid_error(nullptr))};
  return Ok{};
}

std::string hex16(std::uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof text, "%04x", value);
  return text;
}

}  // namespace

std::string hidapi_version() { return hid_version_str(); }

Status check_hidraw_node(const std::string& path) {
  struct stat node {};
  if (::stat(path.c_str(), &node) != 0) return Error{path + ": cannot open the HID device: " + std::strerror(errno)};
  if (!S_ISCHR(node.st_mode)) return Error{path + ": not a hidraw device (not a character device)"};
  // The kernel names the driver of every character device: /sys/dev/char/MAJOR:MINOR/subsystem.
  const std::filesystem::path subsystem = "/sys/dev/char/" + std::to_string(major(node.st_rdev)) + ":" +
                                          std::to_string(minor(node.st_rdev)) + "/subsystem";
  std::error_code ec;
  const std::filesystem::path driver = std::filesystem::read_symlink(subsystem, ec);
  if (ec || driver.filename() != "hidraw") {
    return Error{path + ": not a hidraw device (character device " + std::to_string(major(node.st_rdev)) + ":" +
                 std::to_string(minor(node.st_rdev)) + (ec ? "" : " belongs to " + driver.filename().string()) + ")"};
  }
  return Ok{};
}

Result<std::vector<HidDeviceInfo>> enumerate_hid_devices(std::uint16_t vendor_id, std::uint16_t product_id) {
  if (Status init = ensure_hidapi_initialised(); !init) return Error{init.error()};
  std::vector<HidDeviceInfo> devices;
  hid_device_info* list = hid_enumerate(vendor_id, product_id);
  for (const hid_device_info* it = list; it != nullptr; it = it->next) {
    HidDeviceInfo info;
    info.path = it->path != nullptr ? it->path : "";
    info.vendor_id = it->vendor_id;
    info.product_id = it->product_id;
    info.serial_number = narrow(it->serial_number);
    info.manufacturer = narrow(it->manufacturer_string);
    info.product = narrow(it->product_string);
    info.release_number = it->release_number;
    info.interface_number = it->interface_number;
    devices.push_back(std::move(info));
  }
  hid_free_enumeration(list);
  // hidapi lists in the kernel's order; sort by path so listings and "first match" are stable.
  std::stable_sort(devices.begin(), devices.end(),
                   [](const HidDeviceInfo& a, const HidDeviceInfo& b) { return a.path < b.path; });
  return devices;
}

HidTransport::HidTransport(HidSelector selector) : selector_(std::move(selector)) {}

HidTransport::~HidTransport() { close(); }

std::string HidTransport::describe() const {
  std::string text = "hid " + hex16(selector_.vendor_id) + ":" + hex16(selector_.product_id);
  if (!opened_path_.empty()) text += " at " + opened_path_;
  else if (!selector_.path.empty()) text += " at " + selector_.path;
  if (!selector_.serial_number.empty()) text += " serial " + selector_.serial_number;
  return text;
}

std::string HidTransport::last_error() const { return narrow(hid_error(device_)); }

Status HidTransport::open() {
  close();
  if (Status init = ensure_hidapi_initialised(); !init) return init;
  std::string path = selector_.path;
  if (path.empty()) {
    auto devices = enumerate_hid_devices(selector_.vendor_id, selector_.product_id);
    if (!devices) return Error{devices.error()};
    for (const HidDeviceInfo& info : *devices) {
      if (selector_.serial_number.empty() || info.serial_number == selector_.serial_number) {
        path = info.path;
        break;
      }
    }
    if (path.empty()) {
      return Error{"no HID device " + hex16(selector_.vendor_id) + ":" + hex16(selector_.product_id) +
                   (selector_.serial_number.empty() ? "" : " with serial " + selector_.serial_number) +
                   " found"};
    }
  }
  if (Status node = check_hidraw_node(path); !node) return node;
  device_ = hid_open_path(path.c_str());
  if (device_ == nullptr) return Error{"cannot open HID device " + path + ": " + narrow(hid_error(nullptr))};
  opened_path_ = path;
  return Ok{};
}

void HidTransport::close() {
  if (device_ != nullptr) hid_close(device_);
  device_ = nullptr;
  opened_path_.clear();
}

Result<std::size_t> HidTransport::read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) {
  if (device_ == nullptr) return Error{describe() + ": not open"};
  const std::int64_t timeout_ms = std::clamp<std::int64_t>(
      (timeout_ns + kNanosecondsPerMillisecond - 1) / kNanosecondsPerMillisecond, 0, INT_MAX);
  const int n = hid_read_timeout(device_, buffer.data(), buffer.size(), static_cast<int>(timeout_ms));
  if (n < 0) return Error{describe() + ": read failed: " + last_error()};
  return static_cast<std::size_t>(n);
}

Result<std::size_t> HidTransport::get_feature_report(std::uint8_t report_id, std::span<std::uint8_t> buffer) {
  if (device_ == nullptr) return Error{describe() + ": not open"};
  if (buffer.empty()) return Error{describe() + ": empty feature report buffer"};
  buffer[0] = report_id;
  const int n = hid_get_feature_report(device_, buffer.data(), buffer.size());
  if (n < 0) {
    return Error{describe() + ": get feature report " + std::to_string(report_id) + " failed: " + last_error()};
  }
  return static_cast<std::size_t>(n);
}

Status HidTransport::send_feature_report(std::span<const std::uint8_t> report) {
  if (device_ == nullptr) return Error{describe() + ": not open"};
  if (report.empty()) return Error{describe() + ": empty feature report"};
  const int n = hid_send_feature_report(device_, report.data(), report.size());
  if (n < 0) {
    return Error{describe() + ": send feature report " + std::to_string(report[0]) + " failed: " + last_error()};
  }
  return Ok{};
}

}  // namespace resecto
