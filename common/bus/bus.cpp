#include "marsala/bus/bus.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "marsala/bus/detail/backends.hpp"
#include "marsala/bus/peers.hpp"
#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"

namespace marsala::bus {

namespace {
constexpr EnumName<Vendor> kVendorNames[] = {
    {Vendor::kCyclone, "cyclone"}, {Vendor::kFastDds, "fastdds"}, {Vendor::kInProcess, "inprocess"}};
}  // namespace

std::string to_string(Vendor v) { return enum_to_string(kVendorNames, v); }

std::string WriterId::to_string() const {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string text;
  text.reserve(2 * prefix.size());
  for (std::uint8_t b : prefix) {
    text += kHex[b >> 4];
    text += kHex[b & 0xf];
  }
  return text;
}

Vendor vendor_from_string(const std::string& name) { return enum_from_string(kVendorNames, name, "DDS vendor"); }

int world_discovery_port(int domain_id, int k) {
  // The RTPS port mapping (PB 7400, DG 250, PG 2, d1 10): a participant index i discovers on offset 10 + 2 i.
  constexpr int kPortBase = 7400;
  constexpr int kDomainGain = 250;
  constexpr int kFirstWorldOffset = 2;
  return kPortBase + kDomainGain * domain_id + kFirstWorldOffset + 2 * k;
}

void Signal::notify() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = true;
  }
  cv_.notify_all();
}

bool Signal::wait_for(std::chrono::nanoseconds timeout) {
  return wait_until(std::chrono::steady_clock::now() + timeout);
}

bool Signal::wait_until(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool notified = cv_.wait_until(lock, deadline, [this] { return pending_; });
  pending_ = false;
  return notified;
}

namespace {

const char* profile_variable(Vendor vendor) {
  return vendor == Vendor::kCyclone ? "CYCLONEDDS_URI" : "FASTRTPS_DEFAULT_PROFILES_FILE";
}

/// The folder of the running executable, or empty.
std::filesystem::path executable_dir() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : self.parent_path();
}

/// Throws InvalidArgument when the profile at `path` (an older copy of deploy/dds/*-unicast.xml) still needs the
/// world's address: Cyclone expands ${MARSALA_WORLD_ADDRESS} itself but it is not set; Fast DDS 2.9 expands nothing.
/// The shipped profiles take the address from --peers instead (docs/runtime.md#peers).
void check_world_address(Vendor vendor, const std::string& path) {
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const char* address = std::getenv("MARSALA_WORLD_ADDRESS");
  if (vendor == Vendor::kCyclone && text.find("\"${MARSALA_WORLD_ADDRESS}\"") != std::string::npos &&
      (address == nullptr || *address == '\0'))
    throw InvalidArgument(
        fmt::format("DDS profile '{}' needs MARSALA_WORLD_ADDRESS, the world host's address; or drop its peer and "
                    "give --peers ADDR (docs/runtime.md#peers)",
                    path));
  if (vendor == Vendor::kFastDds && text.find(">${MARSALA_WORLD_ADDRESS}<") != std::string::npos)
    throw InvalidArgument(fmt::format(
        "DDS profile '{}' is a template: Fast DDS 2.9 expands no variables; drop its initial peer and give --peers "
        "ADDR (docs/runtime.md#peers)",
        path));
}

/// Throws InvalidArgument unless `path` is a readable profile document of `vendor`.
void check_profile(Vendor vendor, const std::string& path) {
  std::ifstream in(path);
  if (!in)
    throw InvalidArgument(fmt::format("DDS profile '{}' (--dds-config / MARSALA_DDS_CONFIG) cannot be read", path));
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  const bool cyclone = head.find("<CycloneDDS") != std::string::npos;
  const bool fastdds = head.find("<dds") != std::string::npos || head.find("<profiles") != std::string::npos;
  if (vendor == Vendor::kCyclone && !cyclone)
    throw InvalidArgument(fmt::format("DDS profile '{}' is not a Cyclone DDS profile (no <CycloneDDS> element){}", path,
                                      fastdds ? ": it is a Fast DDS one; use --dds fastdds or a cyclone-*.xml" : ""));
  if (vendor == Vendor::kFastDds && !fastdds)
    throw InvalidArgument(
        fmt::format("DDS profile '{}' is not a Fast DDS profile (no <dds> or <profiles> element){}", path,
                    cyclone ? ": it is a Cyclone DDS one; use --dds cyclone or a fastdds-*.xml" : ""));
  check_world_address(vendor, path);
  if (vendor == Vendor::kFastDds) detail::check_fastdds_profile(path);
}

}  // namespace

std::string resolve_profile(Vendor vendor, const std::string& given, bool unicast) {
  if (vendor == Vendor::kInProcess) return {};
  if (!given.empty()) {
    check_profile(vendor, given);
    return std::filesystem::absolute(given).string();
  }
  if (const char* set = std::getenv(profile_variable(vendor)); set != nullptr && *set != '\0') return {};
  const std::string name =
      std::string(vendor == Vendor::kCyclone ? "cyclone" : "fastdds") + (unicast ? "-unicast.xml" : "-lo.xml");
  std::vector<std::filesystem::path> candidates;
  if (const std::filesystem::path exe = executable_dir(); !exe.empty())
    candidates.push_back(exe.parent_path() / "share" / "marsala" / "dds" / name);
  candidates.push_back(std::filesystem::path(MARSALA_SOURCE_DIR) / "deploy" / "dds" / name);
  for (const std::filesystem::path& c : candidates) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(c, ec)) return c.string();
  }
  return {};
}

namespace {
/// The value of `name=` in the identity folder's manifest, or nullopt when the folder has no manifest or no such line.
std::optional<std::string> manifest_field(const std::filesystem::path& manifest, const std::string& name) {
  std::ifstream in(manifest);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(name + "=", 0) == 0) return line.substr(name.size() + 1);
  return std::nullopt;
}
}  // namespace

void check_security(const Security& security, int domain_id) {
  if (!security.enabled()) return;
  if (security.identity.empty())
    throw InvalidArgument(fmt::format("DDS Security: no identity given for {}", security.dir));
  for (const std::string& name : {std::string("ca.pem"), std::string("governance.p7s"), std::string("permissions.p7s"),
                                  security.identity + ".pem", security.identity + ".key"}) {
    const std::filesystem::path file = std::filesystem::path(security.dir) / name;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
      throw InvalidArgument(fmt::format(
          "DDS Security: {} not found (make the folder with deploy/security/make-identities.sh)", file.string()));
  }
  // A private key others can read is no secret any more: refused, as ssh refuses one.
  const std::filesystem::path key = std::filesystem::path(security.dir) / (security.identity + ".key");
  const std::filesystem::perms others = std::filesystem::perms::group_all | std::filesystem::perms::others_all;
  if ((std::filesystem::status(key).permissions() & others) != std::filesystem::perms::none)
    throw InvalidArgument(
        fmt::format("DDS Security: private key {} is open to other users (chmod 600 it)", key.string()));
  // A folder made for one domain (its manifest, make-identities.sh --domain) says so before DDS refuses it unexplained.
  const std::filesystem::path manifest = std::filesystem::path(security.dir) / "manifest";
  if (const std::optional<std::string> made_for = manifest_field(manifest, "domain");
      made_for && *made_for != "0-230" && *made_for != std::to_string(domain_id))
    throw InvalidArgument(fmt::format("DDS Security: {} was made for domain {}, not domain {} ({})", security.dir,
                                      *made_for, domain_id, manifest.string()));
}

void check_config(const BusConfig& config) {
  if (config.vendor == Vendor::kInProcess && config.security.enabled())
    throw InvalidArgument("DDS Security needs a DDS vendor (cyclone or fastdds), not inprocess");
  check_security(config.security, config.domain_id);
  if (config.domain_id < 0 || config.domain_id > 232)
    throw InvalidArgument(fmt::format("DDS domain id must be in 0..232, got {}", config.domain_id));
  resolve_profile(config.vendor, config.profile, !config.peers.empty());  // a given profile: checked whole
  // A Fast DDS profile from the vendor's own variable: its MARSala properties, when Fast DDS can load it at all (one
  // it cannot load, Fast DDS itself ignores).
  const char* own = std::getenv(profile_variable(Vendor::kFastDds));
  if (config.vendor == Vendor::kFastDds && config.profile.empty() && own != nullptr && *own != '\0') {
    std::error_code ec;
    if (std::filesystem::is_regular_file(own, ec)) detail::check_fastdds_profile(own);
  }
}

std::unique_ptr<Participant> make_participant(const BusConfig& config) {
  check_config(config);
  // The vendors are given addresses: a name is resolved once, here, and one that does not resolve is refused by name.
  BusConfig resolved = config;
  resolved.peers = resolve_peers(config.peers);
  if (const std::string profile = resolve_profile(config.vendor, config.profile, !config.peers.empty());
      !profile.empty()) {
    const std::string value = config.vendor == Vendor::kCyclone ? "file://" + profile : profile;
    ::setenv(profile_variable(config.vendor), value.c_str(), 1);
  }
  std::unique_ptr<Participant> participant;
  switch (config.vendor) {
    case Vendor::kInProcess: return detail::make_inprocess_participant(config.domain_id);
    case Vendor::kCyclone: participant = detail::make_cyclone_participant(resolved); break;
    case Vendor::kFastDds: participant = detail::make_fastdds_participant(resolved); break;
  }
  if (!participant) throw InvalidArgument("unknown DDS vendor");
  if (!resolved.peers.empty())  // said in the world's and agents' logs (a monitor's stdout stays its output)
    spdlog::log(config.role == Role::kServer ? spdlog::level::debug : spdlog::level::info,
                "bus: {} participant in domain {} discovers by unicast only, at {} (--peers; no multicast)",
                to_string(config.vendor), config.domain_id, fmt::join(resolved.peers, ", "));
  return participant;
}

}  // namespace marsala::bus
