#include "service_probe.h"

#include <ros/header.h>
#include <ros/master.h>
#include <ros/network.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace cartpole_qlearning
{
namespace
{
// A header larger than this is no service's (a handful of short fields).
constexpr std::uint32_t kMaxHeaderBytes = 64 * 1024;

class Socket
{
public:
  explicit Socket(int fd) : fd_(fd) {}
  ~Socket()
  {
    if (fd_ >= 0)
      ::close(fd_);
  }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  int fd() const
  {
    return fd_;
  }

private:
  int fd_;
};

bool waitFor(int fd, short events, std::chrono::milliseconds timeout)
{
  pollfd p{fd, events, 0};
  int n;
  do
    n = ::poll(&p, 1, static_cast<int>(timeout.count()));
  while (n < 0 && errno == EINTR);
  return n == 1 && (p.revents & events) != 0;
}

// A connection to host:port within timeout, or -1.
int connectWithin(const std::string& host, std::uint32_t port, std::chrono::milliseconds timeout)
{
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0)
    return -1;
  int fd = -1;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next)
  {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0)
      continue;
    int error = 0;
    socklen_t length = sizeof error;
    const bool connected = ::connect(fd, a->ai_addr, a->ai_addrlen) == 0 ||
                           (errno == EINPROGRESS && waitFor(fd, POLLOUT, timeout) &&
                            ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &length) == 0 && error == 0);
    if (!connected)
    {
      ::close(fd);
      fd = -1;
    }
  }
  ::freeaddrinfo(found);
  return fd;
}

bool sendAll(int fd, const std::uint8_t* data, std::size_t size, std::chrono::milliseconds timeout)
{
  while (size > 0)
  {
    if (!waitFor(fd, POLLOUT, timeout))
      return false;
    const ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL);
    if (n < 0 && (errno == EINTR || errno == EAGAIN))
      continue;
    if (n <= 0)
      return false;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

bool receiveAll(int fd, std::uint8_t* data, std::size_t size, std::chrono::milliseconds timeout)
{
  while (size > 0)
  {
    if (!waitFor(fd, POLLIN, timeout))
      return false;
    const ssize_t n = ::recv(fd, data, size, 0);
    if (n < 0 && (errno == EINTR || errno == EAGAIN))
      continue;
    if (n <= 0)
      return false;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// ROS's wire order for lengths: little-endian 32 bits.
void putLength(std::uint32_t n, std::uint8_t* out)
{
  for (int i = 0; i < 4; ++i)
    out[i] = static_cast<std::uint8_t>(n >> (8 * i));
}
std::uint32_t getLength(const std::uint8_t* in)
{
  return in[0] | (in[1] << 8) | (in[2] << 16) | (static_cast<std::uint32_t>(in[3]) << 24);
}

// The URI of the node serving `service`; Missing when the master says none does.
ServiceFound::Kind lookUp(const std::string& service, const std::string& caller_id, std::string& uri)
{
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = caller_id;
  args[1] = service;
  if (ros::master::execute("lookupService", args, result, payload, false))
  {
    uri = static_cast<std::string>(payload);
    return ServiceFound::Kind::Served;
  }
  // [code, status, uri]: the master answered, with -1 ("no provider") for a service nobody serves.
  const bool answered = result.getType() == XmlRpc::XmlRpcValue::TypeArray && result.size() >= 1 &&
                        result[0].getType() == XmlRpc::XmlRpcValue::TypeInt;
  return answered && static_cast<int>(result[0]) == -1 ? ServiceFound::Kind::Missing : ServiceFound::Kind::Unknown;
}
}  // namespace

ServiceFound probeService(const std::string& service, const std::string& caller_id, std::chrono::milliseconds timeout)
{
  ServiceFound found;
  std::string uri;
  found.kind = lookUp(service, caller_id, uri);
  if (found.kind != ServiceFound::Kind::Served)
    return found;
  found.kind = ServiceFound::Kind::Unknown;
  std::string host;
  std::uint32_t port = 0;
  if (!ros::network::splitURI(uri, host, port))
    return found;
  const Socket socket(connectWithin(host, port, timeout));
  if (socket.fd() < 0)
    return found;

  boost::shared_array<std::uint8_t> header;
  std::uint32_t size = 0;
  ros::Header::write({{"probe", "1"}, {"md5sum", "*"}, {"service", service}, {"callerid", caller_id}}, header, size);
  std::uint8_t length[4];
  putLength(size, length);
  if (!sendAll(socket.fd(), length, 4, timeout) || !sendAll(socket.fd(), header.get(), size, timeout))
    return found;
  if (!receiveAll(socket.fd(), length, 4, timeout))
    return found;
  const std::uint32_t reply_size = getLength(length);
  if (reply_size == 0 || reply_size > kMaxHeaderBytes)
    return found;
  std::vector<std::uint8_t> reply(reply_size);
  if (!receiveAll(socket.fd(), reply.data(), reply.size(), timeout))
    return found;
  ros::Header parsed;
  std::string error;
  std::string type;
  // A header with an error field is the server refusing the probe: nothing found out.
  if (!parsed.parse(reply.data(), reply_size, error) || parsed.getValue("error", error) ||
      !parsed.getValue("type", type))
    return found;
  found.kind = ServiceFound::Kind::Served;
  found.type = type;
  parsed.getValue("md5sum", found.md5sum);
  return found;
}

}  // namespace cartpole_qlearning
