#pragma once
// USB enumeration of PrimeSense sensors with libusb, so that start-up can say exactly what is
// wrong: no sensor on the bus, a sensor the user may not open (missing udev rule), or a sensor
// another program holds.

#include <cstdint>
#include <string>
#include <vector>

namespace ihs::sensor {

/// PrimeSense's USB vendor id.
inline constexpr std::uint16_t kPrimeSenseVendorId = 0x1d27;

/// What we can tell about one PrimeSense device on the bus.
struct UsbDeviceInfo {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  int bus = 0;
  int address = 0;
  /// Model name from the product id ("Carmine 1.09 (USB 3)", …).
  std::string model;
  /// Whether OpenNI2's PS1080 driver handles this product id.
  bool supported = false;
  /// Whether this process may open the device (false: permissions, see UdevRule()).
  bool accessible = false;
  /// Whether another program has claimed the device.
  bool busy = false;
  /// libusb's error text when opening or claiming failed.
  std::string error;
};

/// The result of a bus scan.
struct UsbScan {
  /// False when libusb could not start (no USB subsystem, e.g. in a container).
  bool usb_available = false;
  /// Why libusb could not start, when it could not.
  std::string error;
  /// PrimeSense devices found (any product id of vendor 0x1d27).
  std::vector<UsbDeviceInfo> devices;
};

/// The model name for a PrimeSense product id, and whether OpenNI2's PS1080 driver supports it.
std::string PrimeSenseModel(std::uint16_t product_id, bool* supported = nullptr);

/// Scans the USB bus for PrimeSense devices, probing each for access and for another owner.
/// Never throws; problems are reported in the result.
UsbScan ScanPrimeSenseDevices();

/// The udev rule that gives users access to supported PrimeSense sensors (including the
/// Carmine 1.09 on USB 3, product 0x0609, which stock rules omit), with install instructions.
std::string UdevRuleInstructions();

/// A report for a person: one line per device with its state and, for each problem, the exact fix.
/// `ready` (if given) is set when at least one supported device is accessible and free.
std::string DescribeUsbScan(const UsbScan& scan, bool* ready = nullptr);

}  // namespace ihs::sensor
