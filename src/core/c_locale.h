/* Numbers in files and messages as JSON writes them, whatever the locale of the program
 * the library runs in: a host that calls setlocale(LC_ALL, "") under a comma-decimal
 * locale (GTK, Qt and some Python programs do) would otherwise make strtod refuse
 * "0.100" and printf write "352,5" into an ENVI header. */
#ifndef THZ_CORE_C_LOCALE_H
#define THZ_CORE_C_LOCALE_H

#include <locale.h>

/* strtod in the "C" locale. */
double thz_strtod(const char *text, char **end);

/* Makes the calling thread use the "C" locale until thz_locale_leave(the value it
 * returned); nests. The library's writers and formatters of numbers call it. */
locale_t thz_locale_enter(void);
void thz_locale_leave(locale_t previous);

#endif
