/** \file
How refused calls report their error: an exception, or the error callback set here.

Every constructor and setter of QuatHinge checks its arguments and refuses what has no meaning (NaN/Inf, a zero axis,
the same body twice, a negative impulse, …); the message names the function and the parameter
("btQuaternionHingeConstraint::setLimit: low (nan) must not be NaN"). A refused call changes nothing.

- Built with exceptions (the default, QUATHINGE_EXCEPTIONS=ON): the refusal throws std::invalid_argument with that
  message; the callback below is not called.
- Built without (QUATHINGE_EXCEPTIONS=OFF: -fno-exceptions, QUATHINGE_NO_EXCEPTIONS defined for the library and its
  users): the refusal calls the error callback with the message and returns. A refused constructor still yields a
  safe object: a joint that is disabled, reports no rows and says why (getFault() == BT_QHINGE_FAULT_INVALID_ARGUMENT,
  a fault clearFault() does not clear); a refused deserialization returns null.

No const method reports or throws in either build (getParam of an unknown parameter returns 0).

The callback is process-wide (C style: a function pointer and a user pointer, as Bullet's own hooks). Set it before
joints are used from several threads; it may be called from any thread that calls a QuatHinge setter.

\code
btQuaternionHingeSetErrorCallback([](const char* message, void*) { std::fprintf(stderr, "%s\n", message); }, nullptr);
btQuaternionHingeSetErrorCallback(nullptr, nullptr);  // back to the default (printf)
\endcode
More: docs/MIGRATING.md, "Bad input".
*/
#ifndef BT_QUATERNION_HINGE_ERRORS_H
#define BT_QUATERNION_HINGE_ERRORS_H

#include "quathinge/quathinge_export.h"

/// Receives one refusal: the message (one line, no newline) and the user pointer given with the callback.
typedef void (*btQuaternionHingeErrorCallback)(const char* message, void* userPointer);

/// Installs `callback` (with `userPointer` handed back to it); null restores the default.
QUATHINGE_API void btQuaternionHingeSetErrorCallback(btQuaternionHingeErrorCallback callback, void* userPointer);
/// The callback in effect, and (if `userPointer` is not null) its user pointer.
QUATHINGE_API btQuaternionHingeErrorCallback btQuaternionHingeGetErrorCallback(void** userPointer);
/// Hands `message` to the callback in effect, with its user pointer: what every refusal does in a build without
/// exceptions (and what btQuaternionHingeWorldImporter does with a refused chunk in either build).
QUATHINGE_API void btQuaternionHingeReportError(const char* message);
/// The default: writes "QuatHinge: <message>" and a newline through printf, as Bullet reports its own warnings.
QUATHINGE_API void btQuaternionHingeDefaultErrorCallback(const char* message, void* userPointer);

#endif  // BT_QUATERNION_HINGE_ERRORS_H
