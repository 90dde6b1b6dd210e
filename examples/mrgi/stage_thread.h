// A bounded hand-off between the stages of `mrgi replay` (decode -> runtime -> encode), so that
// decoding the next input and encoding the last output overlap the frame's GPU work while at
// most `capacity` items wait between two stages (memory stays bounded, latency too).
// StageThread runs one stage on its own thread; the first exception it throws (CommandFailure
// from take()/fail_with) closes its queues and is rethrown by join() on the calling thread.
#pragma once
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

namespace mrgi::tool {

template <class T>
class BoundedQueue {
  // (StageThread's destructor joins: close the queues it waits on before it is destroyed.)
 public:
  explicit BoundedQueue(size_t capacity) : capacity_(capacity ? capacity : 1) {}
  // Blocks while full. False once the queue was closed (the item is dropped).
  bool push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    if (closed_) return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }
  // Blocks while empty. Nothing once closed and drained.
  std::optional<T> pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return item;
  }
  // No more items: pop() drains what is queued, push() refuses.
  void close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    not_empty_.notify_all();
    not_full_.notify_all();
  }

 private:
  size_t capacity_;
  std::mutex mutex_;
  std::condition_variable not_full_, not_empty_;
  std::deque<T> items_;
  bool closed_ = false;
};

class StageThread {
 public:
  // Runs `body` on a new thread; `on_exit` runs after it, also when it throws (close the
  // stage's queues there so the neighbours do not wait forever).
  StageThread(std::function<void()> body, std::function<void()> on_exit)
      : thread_([this, body = std::move(body), on_exit = std::move(on_exit)] {
          try {
            body();
          } catch (...) {
            error_ = std::current_exception();
          }
          on_exit();
        }) {}
  ~StageThread() {
    if (thread_.joinable()) thread_.join();
  }
  // Waits for the stage and rethrows its exception, if it had one.
  void join() {
    if (thread_.joinable()) thread_.join();
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

 private:
  std::exception_ptr error_;
  std::thread thread_;
};

// Items a later stage is done with, handed back to the thread that owns their source: the
// encoder returns frame outputs to the runtime's thread, which recycles them
// (Runtime::recycle is not thread-safe); never blocks the encoder.
template <class T>
class ReturnQueue {
 public:
  void put(T&& item) {
    std::lock_guard<std::mutex> lock(mutex_);
    items_.push_back(std::move(item));
  }
  std::deque<T> take_all() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::deque<T> out;
    out.swap(items_);
    return out;
  }

 private:
  std::mutex mutex_;
  std::deque<T> items_;
};

}  // namespace mrgi::tool
