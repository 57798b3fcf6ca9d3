// Work on threads: the two ways backbone runs work beside the calling thread.
//
// run_tasks is a parallel loop: tasks 0..tasks-1 on a few threads, the calling thread among
// them, each thread taking the next task not yet taken (the finite-difference Jacobian's columns
// and colours). SerialQueue is one thread that runs the tasks pushed onto it, one at a time, in
// the order they were pushed (the branch-point detector's sampling and locating threads): what a
// task leaves for the next comes in the same order as on the caller's thread, so the results are
// the same bits with or without it. Neither changes what a task computes; each task must write
// only its own outputs (run_tasks) or data no other thread touches meanwhile (SerialQueue).
//
//   run_tasks(n, 2, [&](int j) { column(j); });   // returns when all n have run
//   SerialQueue queue;
//   queue.push([&] { locate(candidate); });       // returns at once
//   queue.wait();                                 // every task pushed has run; rethrows
#pragma once

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace backbone::core {

// Runs task(0), ..., task(tasks - 1) on min(threads, tasks) threads (at least 1; the calling
// thread is one of them), each thread taking the next task not yet taken. Dynamic, not striped,
// because the cores of a shared virtual machine do not run at one speed (core/README.md,
// 'Threads'). Each task must write only its own outputs, so the result does not depend on which
// thread ran what.
void run_tasks(int tasks, int threads, const std::function<void(int)>& task);

// A thread that runs tasks in the order they were pushed. wait() returns when every task pushed
// has run, and rethrows the first exception a task threw (the later tasks still run: the caller
// goes on and learns of it when it asks, wait() or rethrow()). The destructor drops the tasks
// not begun and joins the thread.
class SerialQueue {
 public:
  SerialQueue();
  ~SerialQueue();
  SerialQueue(const SerialQueue&) = delete;
  SerialQueue& operator=(const SerialQueue&) = delete;

  void push(std::function<void()> task);
  // Blocks until no task is queued or running; then rethrows the first exception a task threw.
  void wait();
  // Rethrows the first exception a task threw so far, without waiting.
  void rethrow();

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable wake_;  // a task came, or stop
  std::condition_variable idle_;  // a task ended
  std::deque<std::function<void()>> tasks_;
  bool busy_ = false, stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: started once the rest exists
};

}  // namespace backbone::core
