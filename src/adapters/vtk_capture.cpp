/*
 * vtk_capture.cpp - VTK's messages into st_error (see vtk_capture.h), and
 * VTK's decompressors for the pre-flight check (st_vtkxml_inflate_vtk,
 * vtkxml.h).
 */
#include "vtk_capture.h"
#include "../io/vtkxml.h"

#include <vtkDataCompressor.h>
#include <vtkLZ4DataCompressor.h>
#include <vtkLZMADataCompressor.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkZLibDataCompressor.h>

#include <cstring>

namespace {

/* What VTK reported on this thread during the current Capture. */
thread_local std::string t_errors;
thread_local int t_capturing = 0;

/* A runaway loop of messages must not eat memory. */
const size_t kMaxCollected = 16384;

class CaptureWindow : public vtkOutputWindow {
public:
    static CaptureWindow *New();
    vtkTypeMacro(CaptureWindow, vtkOutputWindow);

    void SetPrevious(vtkOutputWindow *w)
    {
        if (w)
            w->Register(this);
        prev_ = w;
    }

    void DisplayText(const char *text) override
    {
        if (!text)
            return;
        if (t_capturing) {
            if (GetCurrentMessageType() == MESSAGE_TYPE_ERROR &&
                t_errors.size() < kMaxCollected)
                t_errors += text;
            return;
        }
        if (!prev_)
            return;
        switch (GetCurrentMessageType()) {
        case MESSAGE_TYPE_ERROR: prev_->DisplayErrorText(text); break;
        case MESSAGE_TYPE_WARNING: prev_->DisplayWarningText(text); break;
        case MESSAGE_TYPE_GENERIC_WARNING:
            prev_->DisplayGenericWarningText(text);
            break;
        case MESSAGE_TYPE_DEBUG: prev_->DisplayDebugText(text); break;
        default: prev_->DisplayText(text); break;
        }
    }

protected:
    CaptureWindow() = default;
    ~CaptureWindow() override
    {
        if (prev_)
            prev_->UnRegister(this);
    }

private:
    vtkOutputWindow *prev_ = nullptr;
};
vtkStandardNewMacro(CaptureWindow);

/* One VTK message without its "ERROR: In FILE, line N" header and the
 * "ClassName (0x...): " prefix, on one line. */
std::string clean_message(std::string s)
{
    size_t nl = s.find('\n');
    if (s.compare(0, 3, "ERR") == 0 || s.compare(0, 4, "Warn") == 0 ||
        s.compare(0, 7, "Generic") == 0)
        s = nl == std::string::npos ? "" : s.substr(nl + 1);
    size_t p = s.find("): ");
    if (p != std::string::npos && p < 80)
        s = s.substr(p + 3);
    for (char &c : s)
        if (c == '\n' || c == '\r')
            c = ' ';
    while (!s.empty() && s.back() == ' ')
        s.pop_back();
    return s;
}

} // namespace

namespace st_vtk {

void install()
{
    // A function-local static: initialised once, thread-safely.
    static const bool done = [] {
        vtkOutputWindow *cur = vtkOutputWindow::GetInstance();
        const bool is_default =
            cur && std::strcmp(cur->GetClassName(), "vtkOutputWindow") == 0;
        CaptureWindow *w = CaptureWindow::New();
        if (cur && !is_default)
            w->SetPrevious(cur);   // the program's own window
        else
            // VTK 9 also hands every error and warning to its logger
            // (loguru) before the output window, and the logger writes
            // ERROR and WARNING lines to stderr by default, whole pipeline
            // dumps included. A program that left VTK's messaging at its
            // defaults wants none of that from a library.
            vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
        vtkOutputWindow::SetInstance(w);
        w->Delete();   // SetInstance holds a reference
        return true;
    }();
    (void)done;
}

Capture::Capture()
{
    if (t_capturing++ == 0)
        t_errors.clear();
}

Capture::~Capture()
{
    t_capturing--;
}

bool failed()
{
    return !t_errors.empty();
}

std::string message()
{
    // The messages each end with a blank line. The executive's "Algorithm
    // ... returned failure for request" (followed by a dump of the whole
    // request) says nothing new: left out.
    std::string out;
    const std::string &all = t_errors;
    size_t start = 0;
    while (start < all.size() && out.size() < 400) {
        size_t end = all.find("\n\n", start);
        if (end == std::string::npos)
            end = all.size();
        std::string m = clean_message(all.substr(start, end - start));
        start = end + 2;
        if (m.empty() ||
            m.find("returned failure for request") != std::string::npos ||
            out.find(m) != std::string::npos)
            continue;
        out += (out.empty() ? "" : "; ") + m;
    }
    if (out.size() > 400)
        out = out.substr(0, 400) + "...";
    return out;
}

st_status fail(const char *name, const char *what, st_error *err)
{
    std::string m = message();
    return st_error_set(err, ST_EINPUT, name, 0, "%s%s%s", what,
                        m.empty() ? "" : ": ", m.c_str());
}

} // namespace st_vtk

extern "C" size_t st_vtkxml_inflate_vtk(void *user, const char *compressor,
                                        const unsigned char *in, size_t n,
                                        unsigned char *out, size_t cap)
{
    (void)user;
    try {
        // VTK's own classes: the check inflates exactly what VTK would.
        // Their errors go to the collecting window like any other.
        st_vtk::install();
        st_vtk::Capture cap_messages;
        auto run = [&](vtkDataCompressor *c) {
            return c->Uncompress(in, n, out, cap);
        };
        if (std::strcmp(compressor, "vtkZLibDataCompressor") == 0) {
            vtkNew<vtkZLibDataCompressor> c;
            return run(c);
        }
        if (std::strcmp(compressor, "vtkLZ4DataCompressor") == 0) {
            vtkNew<vtkLZ4DataCompressor> c;
            return run(c);
        }
        if (std::strcmp(compressor, "vtkLZMADataCompressor") == 0) {
            vtkNew<vtkLZMADataCompressor> c;
            return run(c);
        }
    } catch (...) {
    }
    return 0;
}
