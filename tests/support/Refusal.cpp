#include "support/Refusal.h"

#include "quathinge/btQuaternionHingeErrors.h"

#ifndef QUATHINGE_NO_EXCEPTIONS
#include <stdexcept>
#endif

namespace qh_test
{
namespace
{
void capture(const char* message, void* user)
{
	ErrorCapture& self = *static_cast<ErrorCapture*>(user);
	if (self.count++ == 0) self.first = message;
}
}  // namespace

ErrorCapture::ErrorCapture()
{
	m_previous = btQuaternionHingeGetErrorCallback(&m_previousUser);
	btQuaternionHingeSetErrorCallback(capture, this);
}

ErrorCapture::~ErrorCapture() { btQuaternionHingeSetErrorCallback(m_previous, m_previousUser); }

::testing::AssertionResult refused(const std::function<void()>& call, const std::string& parameter)
{
#ifdef QUATHINGE_NO_EXCEPTIONS
	ErrorCapture errors;
	call();
	if (errors.count == 0) return ::testing::AssertionFailure() << "accepted, expected a refusal naming " << parameter;
	if (errors.count != 1)
		return ::testing::AssertionFailure() << errors.count << " reports for one call (first: " << errors.first << ")";
	if (errors.first.find(parameter) == std::string::npos)
		return ::testing::AssertionFailure() << errors.first << " does not name " << parameter;
	return ::testing::AssertionSuccess();
#else
	try
	{
		call();
	}
	catch (const std::invalid_argument& e)
	{
		if (std::string(e.what()).find(parameter) == std::string::npos)
			return ::testing::AssertionFailure() << e.what() << " does not name " << parameter;
		return ::testing::AssertionSuccess();
	}
	return ::testing::AssertionFailure() << "accepted, expected a refusal naming " << parameter;
#endif
}

::testing::AssertionResult accepted(const std::function<void()>& call)
{
	ErrorCapture errors;
#ifdef QUATHINGE_NO_EXCEPTIONS
	call();
#else
	try
	{
		call();
	}
	catch (const std::exception& e)
	{
		return ::testing::AssertionFailure() << "refused: " << e.what();
	}
#endif
	if (errors.count != 0) return ::testing::AssertionFailure() << "reported: " << errors.first;
	return ::testing::AssertionSuccess();
}
}  // namespace qh_test
