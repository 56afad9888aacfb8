#include "byte_input.hpp"

#include "input_file.hpp"

#include <cf/types.hpp>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <unistd.h>

namespace cf::internal {

ByteInput::ByteInput(int fd, std::size_t size, const std::string& source)
    : fd_(fd), size_(size), source_(source) {}

ByteInput::ByteInput(const char* data, std::size_t size, const std::string& source)
    : data_(data), size_(size), source_(source) {}

ByteInput::~ByteInput() {
  if (fd_ >= 0) ::close(fd_);
}

std::size_t ByteInput::read_at(std::size_t offset, char* dst, std::size_t n) const {
  if (offset >= size_) return 0;
  n = std::min(n, size_ - offset);
  if (data_ != nullptr) {
    std::memcpy(dst, data_ + offset, n);
    return n;
  }
  std::size_t done = 0;
  while (done < n) {
    const ssize_t got = ::pread(fd_, dst + done, n - done, static_cast<off_t>(offset + done));
    if (got < 0) {
      if (errno == EINTR) continue;
      throw Error("reading '" + source_ + "': " + read_error(errno));
    }
    if (got == 0) break;  // the file shrank while it was read: its end is here
    done += static_cast<std::size_t>(got);
  }
  return done;
}

ByteInputBuf::int_type ByteInputBuf::underflow() {
  if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
  const std::size_t n = in_.read_at(next_, buf_.data(), buf_.size());
  if (n == 0) return traits_type::eof();
  next_ += n;
  setg(buf_.data(), buf_.data(), buf_.data() + n);
  return traits_type::to_int_type(*gptr());
}

}  // namespace cf::internal
