#include "hardware_counters.hpp"

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <utility>

#include "cellrt/error.hpp"

#ifdef __linux__
#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace cellrt::profile {

#ifdef __linux__
namespace {

// A group that ran less of its enabled time than this was multiplexed with other events.
constexpr double kMinRunningShare = 0.999;

constexpr const char* kEventNames[] = {"instructions", "cycles", "branches", "branch-misses"};
constexpr std::uint64_t kEventConfigs[] = {PERF_COUNT_HW_INSTRUCTIONS, PERF_COUNT_HW_CPU_CYCLES,
                                           PERF_COUNT_HW_BRANCH_INSTRUCTIONS, PERF_COUNT_HW_BRANCH_MISSES};

// The reason in the words a user can act on.
std::string reason(int err) {
    switch (err) {
        case ENOENT:
        case EOPNOTSUPP:
        case ENODEV:
            return "the processor (or the virtual machine) exposes no such counter";
        case EACCES:
        case EPERM: {
            std::ifstream f("/proc/sys/kernel/perf_event_paranoid");
            std::string level;
            f >> level;
            return "not permitted" + (level.empty() ? std::string() : " (kernel.perf_event_paranoid = " + level + ")");
        }
        case ENOSYS:
            return "the kernel has no performance events";
        default:
            return std::strerror(err);
    }
}

}  // namespace

std::optional<HardwareCounters> HardwareCounters::open(Threads threads, std::string& why) {
    HardwareCounters c;
    for (int e = 0; e < kEvents; ++e) {
        perf_event_attr attr{};
        attr.size = sizeof attr;
        attr.type = PERF_TYPE_HARDWARE;
        attr.config = kEventConfigs[e];
        attr.disabled = e == 0;  // members follow their leader
        attr.exclude_kernel = 1;
        attr.exclude_hv = 1;
        attr.inherit = threads == Threads::calling_and_new;
        attr.read_format = PERF_FORMAT_TOTAL_TIME_ENABLED | PERF_FORMAT_TOTAL_TIME_RUNNING;
        const long fd = ::syscall(SYS_perf_event_open, &attr, 0, -1, e == 0 ? -1 : c.fds_[0], PERF_FLAG_FD_CLOEXEC);
        if (fd < 0) {
            const int err = errno;
            why = std::string("hardware counters unavailable: perf_event_open(") + kEventNames[e] +
                  ") failed: " + reason(err);
            return std::nullopt;
        }
        c.fds_[e] = static_cast<int>(fd);
    }
    return c;
}

void HardwareCounters::enable() {
    if (::ioctl(fds_[0], PERF_EVENT_IOC_ENABLE, PERF_IOC_FLAG_GROUP) != 0)
        throw Error(std::string("enabling the hardware counters failed: ") + std::strerror(errno));
}

void HardwareCounters::disable() {
    if (::ioctl(fds_[0], PERF_EVENT_IOC_DISABLE, PERF_IOC_FLAG_GROUP) != 0)
        throw Error(std::string("disabling the hardware counters failed: ") + std::strerror(errno));
}

EventCounts HardwareCounters::read() const {
    std::uint64_t v[kEvents];
    for (int e = 0; e < kEvents; ++e) {
        std::uint64_t r[3];  // value, time enabled, time running
        if (::read(fds_[e], r, sizeof r) != static_cast<ssize_t>(sizeof r))
            throw Error(std::string("reading the hardware counter '") + kEventNames[e] + "' failed: " +
                        std::strerror(errno));
        if (static_cast<double>(r[2]) < kMinRunningShare * static_cast<double>(r[1]))
            throw Error(std::string("the hardware counter '") + kEventNames[e] + "' ran " +
                        std::to_string(r[1] ? 100 * r[2] / r[1] : 0) +
                        "% of the time measured (shared with other users of the counters, such as another perf "
                        "session or the NMI watchdog): its count would be an estimate");
        v[e] = r[0];
    }
    return {v[instructions], v[branches], v[mispredictions], v[cycles]};
}

void HardwareCounters::close_all() {
    for (int& fd : fds_) {
        if (fd >= 0) ::close(fd);
        fd = -1;
    }
}

#else

std::optional<HardwareCounters> HardwareCounters::open(Threads, std::string& why) {
    why = "hardware counters unavailable: perf_event_open is Linux only";
    return std::nullopt;
}
void HardwareCounters::enable() {}
void HardwareCounters::disable() {}
EventCounts HardwareCounters::read() const { return {}; }
void HardwareCounters::close_all() {}

#endif

HardwareCounters HardwareCounters::open_or_throw(Threads threads) {
    std::string why;
    std::optional<HardwareCounters> c = open(threads, why);
    if (!c) throw Error(why);
    return std::move(*c);
}

HardwareCounters::HardwareCounters(HardwareCounters&& o) noexcept : fds_(o.fds_) { o.fds_.fill(-1); }

HardwareCounters& HardwareCounters::operator=(HardwareCounters&& o) noexcept {
    if (this != &o) {
        close_all();
        fds_ = std::exchange(o.fds_, {-1, -1, -1, -1});
    }
    return *this;
}

HardwareCounters::~HardwareCounters() { close_all(); }

}  // namespace cellrt::profile
