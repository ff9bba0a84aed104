// The test VM's promises (tests/hw/vm/): run inside it only (ctest label hw).
#include <linux/can.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;

TEST(VmEnvironment, RunsAsRootWithTheModulesTheTestsNeed) {
  EXPECT_EQ(::geteuid(), 0u) << "the hw tests create vcan interfaces, uhid devices and gpio-sim chips";
  for (const char* module : {"vcan", "can_raw", "uhid", "hid_generic", "gpio_sim"})
    EXPECT_TRUE(fs::exists(fs::path("/sys/module") / module)) << "module " << module << " is not loaded";
}

TEST(VmEnvironment, HasTheDeviceNodesAndConfigfs) {
  EXPECT_TRUE(fs::exists("/dev/uhid"));
  EXPECT_TRUE(fs::is_directory("/sys/kernel/config/gpio-sim")) << "configfs not mounted or gpio-sim missing";
  EXPECT_TRUE(fs::is_directory("/sys/class/hidraw"));
}

TEST(VmEnvironment, OpensARawCanSocket) {
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  EXPECT_GE(fd, 0) << "PF_CAN: " << std::strerror(errno);
  if (fd >= 0) ::close(fd);
}

TEST(VmEnvironment, LoopbackIsUpAndTmpdirIsWritable) {
  EXPECT_NE(::if_nametoindex("lo"), 0u);
  std::ifstream flags("/sys/class/net/lo/flags");
  unsigned long value = 0;
  flags >> std::hex >> value;
  EXPECT_TRUE(value & 0x1) << "lo is down";  // IFF_UP
  const char* tmp = std::getenv("TMPDIR");
  ASSERT_NE(tmp, nullptr);
  const fs::path probe = fs::path(tmp) / "posefair-vm-probe";
  std::ofstream(probe) << "x";
  EXPECT_TRUE(fs::exists(probe)) << tmp << " is not writable";
  fs::remove(probe);
}

}  // namespace
