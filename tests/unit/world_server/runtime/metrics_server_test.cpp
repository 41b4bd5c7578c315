#include "marsala/world_server/runtime/metrics_server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>

#include "marsala/core/error.hpp"
#include "marsala/world_server/runtime/metrics_exposition.hpp"
#include "support/busy_port.hpp"

namespace marsala::world_server {
namespace {

/// A port of loopback that was free a moment ago.
int free_port() { return marsala::testing::BusyPort().port(); }

/// The body of GET `path` from 127.0.0.1:`port` over HTTP/1.0 (headers dropped).
std::string http_get(int port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return "(no connection)";
  }
  const std::string request = "GET " + path + " HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n";
  if (::send(fd, request.data(), request.size(), 0) != static_cast<ssize_t>(request.size())) return "(not sent)";
  std::string response;
  char buffer[4096];
  for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) response.append(buffer, static_cast<std::size_t>(n));
  ::close(fd);
  const auto body = response.find("\r\n\r\n");
  return body == std::string::npos ? response : response.substr(body + 4);
}

TEST(MetricsServer, ServesTheLatestSnapshotRendered) {
  MetricsOptions o;
  o.port = free_port();
  MetricsServer server(o);
  const std::string empty = render_metrics(MetricsSnapshot());
  EXPECT_EQ(http_get(o.port, "/metrics").substr(0, empty.size()), empty);  // before the first publish
  auto s = std::make_shared<MetricsSnapshot>();
  s->run_id = "first";
  s->steps = 12;
  server.publish(s);
  auto t = std::make_shared<MetricsSnapshot>(*s);
  t->steps = 13;
  server.publish(t);
  const std::string text = http_get(o.port, "/metrics");
  const std::string rendered = render_metrics(*t);
  EXPECT_EQ(text.substr(0, rendered.size()), rendered);
  // then this process's own numbers, read at the scrape
  EXPECT_NE(text.find("\nprocess_cpu_seconds_total ", rendered.size() - 1), std::string::npos) << text;
  const auto rss = text.find("\nprocess_resident_memory_bytes ");
  ASSERT_NE(rss, std::string::npos);
  EXPECT_GT(std::stod(text.substr(rss + 31)), 1e6);  // a test process holds more than a megabyte
  EXPECT_NE(text.find("\nmarsala_steps_total 13\n"), std::string::npos) << text;
  EXPECT_EQ(server.scrapes(), 2u);
  EXPECT_EQ(server.latest()->steps, 13u);
}

TEST(MetricsServer, APortInUseIsRefusedNamingIt) {
  const marsala::testing::BusyPort taken;
  MetricsOptions o;
  o.port = taken.port();
  try {
    MetricsServer server(o);
    FAIL() << "listened on a port in use";
  } catch (const InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(fmt::format("--metrics-port {}: cannot listen on 127.0.0.1 port {}", o.port, o.port)),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("in use"), std::string::npos) << what;
  }
}

TEST(MetricsServer, BadPortsAndAddressesAreRefused) {
  MetricsOptions o;
  o.port = 70000;
  EXPECT_THROW(MetricsServer{o}, InvalidArgument);
  o.port = free_port();
  o.address = "localhost-ish";
  EXPECT_THROW(MetricsServer{o}, InvalidArgument);
}

}  // namespace
}  // namespace marsala::world_server
