#include "sensor/usb_devices.h"

#include <gtest/gtest.h>

namespace ihs::sensor {
namespace {

UsbDeviceInfo Device(std::uint16_t product, bool accessible, bool busy) {
  UsbDeviceInfo device;
  device.vendor_id = kPrimeSenseVendorId;
  device.product_id = product;
  device.bus = 2;
  device.address = 7;
  device.model = PrimeSenseModel(product, &device.supported);
  device.accessible = accessible;
  device.busy = busy;
  device.error = accessible ? "" : "Access denied (insufficient permissions)";
  return device;
}

TEST(UsbDevicesTest, KnowsTheCarmineProductIdsIncludingUsb3) {
  bool supported = false;
  EXPECT_NE(PrimeSenseModel(0x0609, &supported).find("Carmine 1.09 on USB 3"), std::string::npos);
  EXPECT_TRUE(supported);
  for (std::uint16_t product : {0x0500, 0x0600, 0x0601}) {
    PrimeSenseModel(product, &supported);
    EXPECT_TRUE(supported) << product;
  }
  EXPECT_NE(PrimeSenseModel(0x1280, &supported).find("0x1280"), std::string::npos);
  EXPECT_FALSE(supported);
}

TEST(UsbDevicesTest, UdevRuleCoversEverySupportedProductId) {
  const std::string rule = UdevRuleInstructions();
  for (const char* product : {"0500", "0600", "0601", "0609"}) {
    EXPECT_NE(rule.find(std::string("ATTR{idProduct}==\"") + product + "\""), std::string::npos)
        << product;
  }
  EXPECT_NE(rule.find("ATTR{idVendor}==\"1d27\""), std::string::npos);
  EXPECT_NE(rule.find("udevadm control --reload-rules"), std::string::npos);
}

TEST(UsbDevicesTest, DescribesEachSituationWithItsFix) {
  bool ready = true;
  UsbScan empty;
  empty.usb_available = true;
  EXPECT_NE(DescribeUsbScan(empty, &ready).find("No PrimeSense device"), std::string::npos);
  EXPECT_FALSE(ready);

  UsbScan denied = empty;
  denied.devices = {Device(0x0609, false, false)};
  const std::string denied_text = DescribeUsbScan(denied, &ready);
  EXPECT_NE(denied_text.find("present but not accessible"), std::string::npos) << denied_text;
  EXPECT_NE(denied_text.find("55-primesense-usb.rules"), std::string::npos);
  EXPECT_FALSE(ready);

  UsbScan busy = empty;
  busy.devices = {Device(0x0601, true, true)};
  EXPECT_NE(DescribeUsbScan(busy, &ready).find("busy"), std::string::npos);
  EXPECT_FALSE(ready);

  UsbScan good = empty;
  good.devices = {Device(0x1280, true, false), Device(0x0601, true, false)};
  const std::string good_text = DescribeUsbScan(good, &ready);
  EXPECT_TRUE(ready);
  EXPECT_NE(good_text.find("bus 002 device 007: ready"), std::string::npos) << good_text;

  UsbScan no_usb;
  no_usb.error = "Other error";
  EXPECT_NE(DescribeUsbScan(no_usb, &ready).find("USB is not available"), std::string::npos);
}

TEST(UsbDevicesTest, ScanningTheRealBusNeverThrowsAndListsOnlyPrimeSenseDevices) {
  const UsbScan scan = ScanPrimeSenseDevices();
  for (const UsbDeviceInfo& device : scan.devices) EXPECT_EQ(device.vendor_id, kPrimeSenseVendorId);
  if (!scan.usb_available) {
    EXPECT_FALSE(scan.error.empty());
  }
}

}  // namespace
}  // namespace ihs::sensor
