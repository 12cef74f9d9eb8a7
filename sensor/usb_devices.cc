#include "sensor/usb_devices.h"

#include <libusb.h>

#include <cstdio>
#include <sstream>

namespace ihs::sensor {
namespace {

struct KnownModel {
  std::uint16_t product_id;
  const char* name;
};

// The product ids OpenNI2's PS1080 driver opens.
constexpr KnownModel kSupported[] = {
    {0x0500, "PrimeSense PS1080 sensor (0x0500)"},
    {0x0600, "PrimeSense Carmine 1.08 / Xtion (0x0600)"},
    {0x0601, "PrimeSense Carmine 1.09 (0x0601)"},
    {0x0609, "PrimeSense Carmine 1.09 on USB 3 (0x0609)"},
};

}  // namespace

std::string PrimeSenseModel(std::uint16_t product_id, bool* supported) {
  for (const KnownModel& model : kSupported) {
    if (model.product_id == product_id) {
      if (supported) *supported = true;
      return model.name;
    }
  }
  if (supported) *supported = false;
  char text[64];
  std::snprintf(text, sizeof(text), "PrimeSense device 0x%04x (not a PS1080 sensor)", product_id);
  return text;
}

UsbScan ScanPrimeSenseDevices() {
  UsbScan scan;
  libusb_context* context = nullptr;
  const int init = libusb_init(&context);
  if (init != LIBUSB_SUCCESS) {
    scan.error = libusb_strerror(static_cast<libusb_error>(init));
    return scan;
  }
  scan.usb_available = true;
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(context, &list);
  if (count < 0) {
    scan.usb_available = false;
    scan.error = libusb_strerror(static_cast<libusb_error>(count));
    libusb_exit(context);
    return scan;
  }
  for (ssize_t i = 0; i < count; ++i) {
    libusb_device_descriptor descriptor{};
    if (libusb_get_device_descriptor(list[i], &descriptor) != LIBUSB_SUCCESS) continue;
    if (descriptor.idVendor != kPrimeSenseVendorId) continue;
    UsbDeviceInfo info;
    info.vendor_id = descriptor.idVendor;
    info.product_id = descriptor.idProduct;
    info.bus = libusb_get_bus_number(list[i]);
    info.address = libusb_get_device_address(list[i]);
    info.model = PrimeSenseModel(info.product_id, &info.supported);
    libusb_device_handle* handle = nullptr;
    const int opened = libusb_open(list[i], &handle);
    if (opened == LIBUSB_SUCCESS) {
      info.accessible = true;
      // Claiming interface 0 fails with BUSY while another program streams from the sensor.
      const int claimed = libusb_claim_interface(handle, 0);
      if (claimed == LIBUSB_SUCCESS) {
        libusb_release_interface(handle, 0);
      } else if (claimed == LIBUSB_ERROR_BUSY) {
        info.busy = true;
        info.error = libusb_strerror(static_cast<libusb_error>(claimed));
      }
      libusb_close(handle);
    } else {
      info.accessible = opened != LIBUSB_ERROR_ACCESS;
      info.busy = opened == LIBUSB_ERROR_BUSY;
      info.error = libusb_strerror(static_cast<libusb_error>(opened));
    }
    scan.devices.push_back(info);
  }
  libusb_free_device_list(list, 1);
  libusb_exit(context);
  return scan;
}

std::string UdevRuleInstructions() {
  std::ostringstream text;
  text << "Install this udev rule as /etc/udev/rules.d/55-primesense-usb.rules:\n";
  for (const KnownModel& model : kSupported) {
    char line[200];
    std::snprintf(line, sizeof(line),
                  "SUBSYSTEM==\"usb\", ATTR{idVendor}==\"%04x\", ATTR{idProduct}==\"%04x\", "
                  "MODE=\"0666\", GROUP=\"plugdev\"\n",
                  kPrimeSenseVendorId, model.product_id);
    text << "  " << line;
  }
  text << "then run: sudo udevadm control --reload-rules && sudo udevadm trigger, and re-plug the "
          "sensor.";
  return text.str();
}

std::string DescribeUsbScan(const UsbScan& scan, bool* ready) {
  std::ostringstream text;
  bool any_ready = false, needs_rule = false;
  if (!scan.usb_available) {
    text << "USB is not available to this process (" << scan.error
         << "); in a container, pass the USB bus through (e.g. --device /dev/bus/usb).\n";
  } else if (scan.devices.empty()) {
    text << "No PrimeSense device on the USB bus: plug the sensor in (a Carmine needs a powered "
            "USB port) and check `lsusb` for vendor 1d27.\n";
  }
  for (const UsbDeviceInfo& device : scan.devices) {
    char where[64];
    std::snprintf(where, sizeof(where), "bus %03d device %03d", device.bus, device.address);
    text << device.model << " at " << where << ": ";
    if (!device.supported) {
      text << "not a depth sensor OpenNI2's PS1080 driver opens.\n";
    } else if (!device.accessible) {
      text << "present but not accessible (" << device.error << ").\n";
      needs_rule = true;
    } else if (device.busy) {
      text << "present but busy: another program is using it; close it (e.g. another "
              "inhandscan, NiViewer) and try again.\n";
    } else {
      text << "ready.\n";
      any_ready = true;
    }
  }
  if (needs_rule) text << UdevRuleInstructions() << "\n";
  if (ready) *ready = any_ready;
  return text.str();
}

}  // namespace ihs::sensor
