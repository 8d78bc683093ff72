#include "core/c_locale.h"

#include <pthread.h>
#include <stdlib.h>

static locale_t c_locale = (locale_t)0;
static pthread_once_t c_locale_once = PTHREAD_ONCE_INIT;

static void c_locale_make(void)
{
    c_locale = newlocale(LC_ALL_MASK, "C", (locale_t)0);
}

locale_t thz_locale_enter(void)
{
    pthread_once(&c_locale_once, c_locale_make);
    /* Without memory for the object, the thread keeps its locale (as before this file). */
    return c_locale ? uselocale(c_locale) : (locale_t)0;
}

void thz_locale_leave(locale_t previous)
{
    if (previous)
        uselocale(previous);
}

double thz_strtod(const char *text, char **end)
{
    locale_t previous = thz_locale_enter();
    double v = strtod(text, end);
    thz_locale_leave(previous);
    return v;
}
