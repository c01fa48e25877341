// The process-wide error callback of builds without exceptions (btQuaternionHingeErrors.h). Its own file, in the
// library proper and exported: one callback state however many programs and libraries use the argument checks.
#include "quathinge/btQuaternionHingeErrors.h"

#include <cstdio>

namespace
{
btQuaternionHingeErrorCallback g_callback = btQuaternionHingeDefaultErrorCallback;
void* g_userPointer = nullptr;
}  // namespace

void btQuaternionHingeDefaultErrorCallback(const char* message, void* /*userPointer*/)
{
	std::printf("QuatHinge: %s\n", message);
}

void btQuaternionHingeSetErrorCallback(btQuaternionHingeErrorCallback callback, void* userPointer)
{
	g_callback = callback ? callback : btQuaternionHingeDefaultErrorCallback;
	g_userPointer = callback ? userPointer : nullptr;
}

btQuaternionHingeErrorCallback btQuaternionHingeGetErrorCallback(void** userPointer)
{
	if (userPointer) *userPointer = g_userPointer;
	return g_callback;
}


void btQuaternionHingeReportError(const char* message) { g_callback(message, g_userPointer); }
