# daemon/: obscurad.  Included by the top Makefile (after protocol.mk).
MHD_CFLAGS := $(shell pkg-config --cflags libmicrohttpd 2>/dev/null)
MHD_LIBS := $(shell pkg-config --libs libmicrohttpd 2>/dev/null || echo -lmicrohttpd)
PKG_CFLAGS += $(MHD_CFLAGS)
EXTRA_LIBS += $(MHD_LIBS)

DAEMON_SRC := $(wildcard daemon/*.c)
DAEMON_OBJ := $(DAEMON_SRC:%.c=$(BUILD)/obj/%.o)
DAEMON_MAIN := $(BUILD)/obj/daemon/obscurad.o
# Everything but main, for the unit tests under tests/unit/daemon.
DAEMON_LIB := $(BUILD)/libobscurad.a
OBSCURAD := $(BUILD)/obscurad

EXTRA_BINS += $(OBSCURAD)
E2E_DEPS += $(OBSCURAD)

$(BUILD)/obj/daemon/%.o: CPPFLAGS += -Iprotocol

# The preview page (daemon/preview) is embedded into the daemon.
PAGE_FILES := $(sort $(wildcard daemon/preview/*))
PAGE_HDR := $(BUILD)/gen/obsd_page.h
$(PAGE_HDR): $(PAGE_FILES) tools/embed_files.sh
	@mkdir -p $(dir $@)
	tools/embed_files.sh $(PAGE_FILES) > $@.tmp && mv $@.tmp $@
$(BUILD)/obj/daemon/http_page.o: $(PAGE_HDR)

$(DAEMON_LIB): $(filter-out $(DAEMON_MAIN),$(DAEMON_OBJ))
	@rm -f $@
	ar rcs $@ $^

$(OBSCURAD): $(DAEMON_MAIN) $(DAEMON_LIB) $(PROTO_LIB) $(LIB)
	$(CC) $(LDFLAGS) -o $@ $(DAEMON_MAIN) $(DAEMON_LIB) $(PROTO_LIB) $(LIB) $(PKG_LIBS) $(EXTRA_LIBS)

# Unit tests of the daemon's parts see its headers and link its library
# (a more specific pattern than the Makefile's, so make prefers it).
$(BUILD)/tests/daemon/%: tests/unit/daemon/%.c $(DAEMON_LIB) $(PROTO_LIB) $(LIB) tests/unit/testutil.h
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CORE_INC) -Idaemon -Iprotocol -Itests/unit $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(DAEMON_LIB) $(PROTO_LIB) $(LIB) $(LDFLAGS) $(PKG_LIBS) $(EXTRA_LIBS) -lcmocka

-include $(DAEMON_OBJ:.o=.d)
