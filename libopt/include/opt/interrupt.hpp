// A process-wide stop request, set from a SIGINT/SIGTERM handler (the app
// installs it) and polled by drivers and studies between evaluations: the
// evaluation under way finishes, then the work stops and what is done is
// written, marked interrupted.
#pragma once

namespace opt {

// True once a stop was requested. Cheap (one relaxed atomic load).
bool stop_requested();
// Requests a stop; async-signal-safe.
void request_stop(int signal = 0);
// The signal that requested the stop (0 if none or not from a signal).
int stop_signal();
// Clears the request (tests).
void clear_stop();
// Installs request_stop as the SIGINT and SIGTERM handler.
void install_stop_handlers();

}  // namespace opt
